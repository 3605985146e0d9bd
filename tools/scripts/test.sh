#!/usr/bin/env bash
# tools/scripts/test.sh — builds the test suite and runs it with CTest.
#
#   bash tools/scripts/test.sh            Release build in build/release, the default suite:
#                                         every test but those labelled long (≤ 8 min, 2 cores)
#   bash tools/scripts/test.sh --all      every test, the long end-to-end runs too (~5 min more)
#   bash tools/scripts/test.sh --asan     ASan+UBSan build in build/asan (renderer off), portable
#   bash tools/scripts/test.sh --portable Release build in build/portable, portable
#   bash tools/scripts/test.sh -- ARGS    extra arguments for ctest (e.g. -- -L stability); a -L,
#                                         -LE, -R or -E of yours replaces the default -LE long
# Portable: -DMAGSIM_NATIVE=OFF, baseline x86-64 and the portable field kernels. Every build
# gives the same golden state hashes on every x86-64 CPU (tests/engine/golden_hashes.txt).
# Installs the Debian packages first if any is missing (tools/scripts/setup.sh --deps-only).
set -euo pipefail
cd "$(dirname "$0")/../.."

preset=release
ctest_args=()
select=(-LE long)
while [ $# -gt 0 ]; do
  case "$1" in
    --asan) preset=asan ;;
    --portable) preset=portable ;;
    --all) select=() ;;
    --) shift; ctest_args=("$@")
        # a label or name selection of the caller's own replaces the default one
        for x in "$@"; do case "$x" in -L|-LE|-R|-E|--label-regex|--label-exclude) select=() ;; esac; done
        break ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "test.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
  shift
done

bash tools/scripts/setup.sh --deps-only
if [ "$preset" = asan ]; then
  cmake -S . -B build/asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMAGSIM_SANITIZE=ON \
        -DMAGSIM_RENDER=OFF -DMAGSIM_NATIVE=OFF >/dev/null
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
elif [ "$preset" = portable ]; then
  cmake -S . -B build/portable -DCMAKE_BUILD_TYPE=Release -DMAGSIM_NATIVE=OFF >/dev/null
else
  cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "build/$preset" -j"$(nproc)"
ctest --test-dir "build/$preset" --output-on-failure -j"$(nproc)" "${select[@]}" "${ctest_args[@]}"
