#!/bin/sh
# Coverage-guided fuzzing of the whole pipeline with AFL++ on stable Rust (Debian: apt-get install afl++).
# Builds fuzz/src/pipeline.rs with LLVM sanitizer coverage (fuzz/rustc-sancov.sh) linked to AFL++'s
# runtime, packs the base scene folders of tests/fuzz_pipeline.rs as seeds, and runs afl-fuzz at the
# lowest priority for SECONDS (default 1800). Crashes land in target/afl/out/default/crashes/; replay one
# with `fuzz/target/release/pipeline FILE`, unpack it into tests/data/fuzz_regressions/ to keep it.
set -eu
cd "$(dirname "$0")/.."
secs=${1:-1800}
# The seeds are the unmutated folders that tests/fuzz_pipeline.rs writes.
cargo test --release --test fuzz_pipeline base_scenes -q >/dev/null
(cd fuzz && RUSTC_WRAPPER="$PWD/rustc-sancov.sh" cargo build --release --bin pipeline)
mkdir -p target/afl/in
for b in target/fuzz-pipeline/base*; do
    fuzz/target/release/pipeline --pack "$b" "target/afl/in/$(basename "$b")"
done
mkdir -p /dev/shm/snee-afl
AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_UI=1 SNEE_FUZZ_DIR=/dev/shm/snee-afl \
    RAYON_NUM_THREADS=1 timeout "$secs" nice -n 19 afl-fuzz -i target/afl/in -o target/afl/out -m 4096 -t 20000 \
    -- fuzz/target/release/pipeline @@ || true
rm -rf /dev/shm/snee-afl
grep -E "execs_done|saved_crashes|saved_hangs|corpus_count|edges_found|total_edges" target/afl/out/default/fuzzer_stats
