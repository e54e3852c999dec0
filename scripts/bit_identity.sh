#!/usr/bin/env bash
# Bit-identity oracle for refactors: render every scenes/*.xml (media scenes also with volpathmis and every
# volpath_snee option) and a few scenes/paper/*.xml at a fixed seed and small spp.
#   scripts/bit_identity.sh render DIR     # write DIR/*.exr with target/release/snee
#   scripts/bit_identity.sh check A B      # pixel-compare A/*.exr with B/*.exr (`snee compare`: MSE exactly 0;
#                                          # the EXR bytes themselves vary with the writer's thread timing)
set -euo pipefail
cd "$(dirname "$0")/.."
SNEE=${SNEE:-target/release/snee}
mode=${1:?usage: render DIR | check A B}

variants() { # scene → lines "name|xml-sed-expression"
    local s=$1
    echo "base|"
    if grep -q '<integrator type="volpath">' "$s"; then
        local r='s|<integrator type="volpath">|<integrator type="%s">%s|'
        printf "mis|$r\n" volpathmis ""
        printf "snee|$r\n" volpath_snee ""
        printf "snee_fwd|$r\n" volpath_snee '<string name="snee" value="forward"/>'
        printf "snee_only|$r\n" volpath_snee '<string name="snee" value="snee"/>'
        printf "snee_tr|$r\n" volpath_snee '<string name="transport" value="snee"/>'
        printf "snee_r1|$r\n" volpath_snee '<float name="snee_rate" value="1"/>'
        printf "snee_r0|$r\n" volpath_snee '<float name="snee_rate" value="0"/>'
    fi
}

if [ "$mode" = render ]; then
    out=${2:?DIR}; mkdir -p "$out"
    tmp=$(mktemp -d)
    for s in scenes/*.xml; do
        n=$(basename "$s" .xml)
        variants "$s" | while IFS='|' read -r v expr; do
            x="$(dirname "$s")/.bit_identity_$n.xml"
            if [ -n "$expr" ]; then sed "$expr" "$s" > "$x"; else cp "$s" "$x"; fi
            "$SNEE" render "$x" -q --seed 7 --spp 16 --threads 2 -o "$out/${n}_$v.exr"
            rm -f "$x"
        done
    done
    for p in sphere_ggx004_st34 directional_smooth_st02 envmap_ggx020_st02 sphere_smooth_st02; do
        for integ in volpath volpath_snee; do
            "$SNEE" render scenes/paper/$p.xml -q --seed 7 --spp 4 --threads 2 -D integrator=$integ \
                -D width=24 -D height=32 -o "$out/paper_${p}_$integ.exr"
        done
    done
    rm -rf "$tmp"
    echo "wrote $(ls "$out"/*.exr | wc -l) images to $out"
elif [ "$mode" = check ]; then
    a=${2:?A}; b=${3:?B}; same=0; diff=0
    for f in "$a"/*.exr; do
        g="$b/$(basename "$f")"
        if [[ "$("$SNEE" compare --json "$f" "$g")" == *'"mse": 0.0,'* ]]; then same=$((same + 1)); else
            diff=$((diff + 1)); echo "DIFFERS: $(basename "$f")"; "$SNEE" compare "$f" "$g" > "$b/$(basename "$f" .exr).txt" || true
            head -6 "$b/$(basename "$f" .exr).txt"
        fi
    done
    echo "identical: $same, different: $diff"
    [ "$diff" = 0 ]
fi
