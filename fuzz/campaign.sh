#!/bin/sh
# Long hostile-input campaign: batches of the property-based pipeline fuzzer (tests/fuzz_pipeline.rs),
# each with a fresh random seed, at the lowest priority and with capped virtual memory (an allocation
# the resource checks miss then aborts the batch, which is reported, instead of exhausting the machine).
# Usage: fuzz/campaign.sh BATCHES [CASES_PER_BATCH] > campaign.log 2>&1
# Totals: grep "cases run" campaign.log; failures: grep -A5 "minimal failing input" campaign.log.
set -u
cd "$(dirname "$0")/.."
batches=${1:-100}
per=${2:-20000}
cargo test --release --test fuzz_pipeline --no-run 2>&1 | tail -1
bin=$(ls -t target/release/deps/fuzz_pipeline-* | grep -v '\.d$' | head -1)
i=0
while [ "$i" -lt "$batches" ]; do
    i=$((i + 1))
    echo "== batch $i ($(date -u +%H:%M:%S))"
    ( ulimit -v 8000000; RUST_BACKTRACE=0 RAYON_NUM_THREADS=1 SNEE_FUZZ_DIR=/dev/shm/snee-fuzz-$$ SNEE_FUZZ_CASES=$per nice -n 19 "$bin" mutated_ --nocapture --test-threads 1 ) 2>&1 \
        | grep -E "cases run|minimal failing|input saved in|^thread .* panicked|^(panic|hang|image error|parse error|build error|non-finite)|test result|memory allocation|signal" \
        || echo "batch $i: no output (rc $?)"
done
rm -rf /dev/shm/snee-fuzz-$$
