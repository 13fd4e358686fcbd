#!/usr/bin/env bash
# The second CI script: builds with AddressSanitizer and UndefinedBehaviorSanitizer
# (clang when present, else gcc) and runs the CPU test suite. LeakSanitizer
# suppresses only leaks inside libhdf5 (scripts/lsan.supp says why).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNEBULA_CUDA=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
cmake --build build-sanitize -j"$(nproc)"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-sanitize
ctest --output-on-failure -j"$(nproc)" -L cpu
# A short fuzz run of the loaders that do not go through libhdf5 (whose own
# crashes on damaged files the child-process read turns into errors; fuzz
# those with scripts/fuzz.sh directly): 20 s each.
cd ..
bash scripts/fuzz.sh 20 scene_text density_fits image_fits
