#!/usr/bin/env bash
# Installs the Debian packages the project builds and tests with.
# Idempotent: installs only what is missing, so a warm machine pays nothing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libtbb-dev libhdf5-dev libcli11-dev libgtest-dev
  libtomlplusplus-dev libcfitsio-dev libopenimageio-dev
  python3-numpy python3-matplotlib python3-h5py python3-venv
  python3-dev pybind11-dev python3-pytest
  # issue 13: animate's MP4 (H.264), the viewer (GLFW, Dear ImGui, OpenGL) and its tests under Xvfb with Mesa
  ffmpeg libglfw3-dev libimgui-dev libgl-dev xvfb xauth libgl1-mesa-dri
  # issue 15: reconstruction of axial maps (non-negative least squares on Eigen, the absorbing fit with Ceres)
  libeigen3-dev libceres-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
