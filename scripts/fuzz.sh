#!/usr/bin/env bash
# Builds the libFuzzer harnesses of the loaders (fuzz/) with clang, ASan and
# UBSan, and runs each for SECONDS (default 30) on a scratch copy of its seed
# corpus (fuzz/corpus/<loader>). Findings land in build-fuzz/artifacts/; turn
# each into a named test of its loader. Usage: scripts/fuzz.sh [SECONDS] [LOADER...]
# NEBULA_FUZZ_CHILD=1 fuzzes the HDF5 loaders through the production path (a
# child process reads each file first), which must turn every libhdf5 crash
# into an error.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
shift || true
loaders=("$@")
[ ${#loaders[@]} -gt 0 ] || loaders=(scene_text density_hdf5 density_fits axial_hdf5 table image_hdf5 image_fits)
command -v clang++ >/dev/null || { echo "fuzz: clang++ is required (apt-get install clang)" >&2; exit 1; }
bash scripts/install-deps.sh
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DNEBULA_CUDA=OFF -DNEBULA_FUZZ=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer" \
  -DCMAKE_C_FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer" >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target $(printf 'fuzz_%s ' "${loaders[@]}")
mkdir -p build-fuzz/artifacts
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
status=0
for loader in "${loaders[@]}"; do
  work=build-fuzz/corpus/$loader
  rm -rf "$work" && mkdir -p "$work" && cp fuzz/corpus/"$loader"/* "$work"/
  echo "fuzz: $loader for ${seconds}s"
  log=build-fuzz/artifacts/"$loader".log
  if ! build-fuzz/bin/fuzz_"$loader" -max_total_time="$seconds" -rss_limit_mb=4096 -max_len=65536 \
      -artifact_prefix=build-fuzz/artifacts/"$loader"- "$work" >"$log" 2>&1; then
    status=1
  fi
  grep -E "^Done [0-9]+ runs|ERROR|SUMMARY|Test unit written" "$log" || true
done
exit $status
