#!/bin/sh
# RUSTC_WRAPPER for fuzz/afl.sh: adds LLVM sanitizer coverage (AFL++'s edge counters) to snee and the
# fuzz target only; dependencies build as usual, so their compiled copies can be reused.
rustc="$1"
shift
case " $* " in
*" --crate-name snee "*)
    exec "$rustc" "$@" -C passes=sancov-module -C llvm-args=-sanitizer-coverage-level=3 \
        -C llvm-args=-sanitizer-coverage-trace-pc-guard -C llvm-args=-sanitizer-coverage-prune-blocks=0 ;;
*" --crate-name pipeline "*)
    exec "$rustc" "$@" -C passes=sancov-module -C llvm-args=-sanitizer-coverage-level=3 \
        -C llvm-args=-sanitizer-coverage-trace-pc-guard -C llvm-args=-sanitizer-coverage-prune-blocks=0 \
        -C link-arg="${AFL_RT:-/usr/lib/afl/afl-compiler-rt.o}" ;;
*) exec "$rustc" "$@" ;;
esac
