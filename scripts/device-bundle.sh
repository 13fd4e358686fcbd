#!/usr/bin/env bash
# Bundles a CUDA build's binaries and the libraries they load for the lent GPU
# machine (which has CUDA but none of our Debian libraries), stripped, into
# .devbundle/ and packed as .devpack/bundle.tar.xz: the binaries' device code
# makes the bundle about 190 MB, over what may travel, and xz -9 takes it to
# about 40 MB (the test binaries share most of their fatbins; its window finds
# them). Build without OpenImageIO first (its libraries are too large to carry):
#   cmake -S . -B build-device -DNEBULA_CUDA=ON -DNEBULA_OPENIMAGEIO=OFF && cmake --build build-device
# then: BUILD=build-device [EXTRA_BINS="..."] scripts/device-bundle.sh, carry .devpack, and run
# scripts/device-run.sh there (it unpacks the archive).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build-device}
bins=("$build"/bin/nebula "$build"/bin/core_tests "$build"/bin/montecarlo_tests "$build"/bin/tables_tests
      "$build"/bin/illumination_tests "$build"/bin/raycast_tests "$build"/bin/axial_tests "$build"/bin/multires_tests
      "$build"/bin/truth_tests "$build"/bin/pipeline_tests "$build"/bin/diffuse_tests)
bins+=("$build"/bin/*_gpu_tests)
# EXTRA_BINS: more binaries to carry (e.g. a baseline build's nebula, copied under
# another name, to time the two builds alternately in one call).
read -r -a extra <<<"${EXTRA_BINS:-}"
bins+=("${extra[@]}")
# The shared tool copies and checks that every library resolves; its size check is
# for an unpacked bundle, so only its other failures stop this script.
if ! log=$(../shared/tools/device-bundle .devbundle "${bins[@]}" -- scenes 2>&1); then
  if ! grep -q "too large" <<<"$log"; then
    echo "$log" >&2
    exit 1
  fi
fi
strip --strip-unneeded .devbundle/bin/*
mkdir -p .devpack
tar -C .devbundle -cf - bin lib data | xz -9 -T2 > .devpack/bundle.tar.xz.tmp
mv .devpack/bundle.tar.xz.tmp .devpack/bundle.tar.xz
echo "device-bundle: .devpack/bundle.tar.xz holds $(du -m .devpack/bundle.tar.xz | cut -f1) MiB (.devbundle/ unpacked: $(du -sm .devbundle | cut -f1) MiB)"
size=$(du -m .devpack/bundle.tar.xz | cut -f1)
[ "$size" -lt 56 ] || { echo "device-bundle: the archive is too large to travel beside the tree; bundle fewer binaries" >&2; exit 1; }
