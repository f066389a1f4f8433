#!/usr/bin/env bash
# Installs what covtrack needs from Debian 12's packages (when missing) and builds it.
# Usage: tools/setup.sh [BUILD_DIR]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}

packages=(build-essential cmake pkg-config liblcm-dev liblcm-bin libeigen3-dev
          libtomlplusplus-dev libcli11-dev libfmt-dev libspdlog-dev nlohmann-json3-dev
          libgtest-dev libgmock-dev libbenchmark-dev libopencv-core-dev libopencv-imgproc-dev
          libopencv-calib3d-dev libopencv-imgcodecs-dev libopencv-videoio-dev libopencv-highgui-dev
          libapriltag-dev libqhull-dev libserial-dev libusb-1.0-0-dev libhidapi-dev libsodium-dev xvfb xauth
          libyaml-cpp-dev libtinyxml2-dev  # camera calibration files (YAML, XML)
          xdotool  # the window tests move the mouse and press keys
          iproute2 util-linux python3-dev pybind11-dev python3-numpy python3-pytest
          default-jdk-headless liblcm-java libjchart2d-java
          libopenscenegraph-dev libgl1-mesa-dri  # the 3-D AR adapter; Mesa draws its tests
          file  # file: cpack -G DEB finds the ELF files for dpkg-shlibdeps with it
          ninja-build  # the build tool of a new build tree (docs/design.md, "Build time")
          clang-16 libclang-rt-16-dev)  # the fuzzers and the sanitized tests (libFuzzer, ASan, UBSan)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# -O2 as every figure in the notes was measured at, without debug info: a quarter less
# compile time on 2 cores. For a debugger: cmake -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo.
# A unity build: each target's sources compiled in batches of up to 8, so that the Eigen
# templates they share are instantiated once a batch, not once a file (CI's build: 908 to
# 702 s). A source's file-local names must then differ from its batch neighbours'
# (docs/design.md, "Build time"). For quick rebuilds of one file: -DCMAKE_UNITY_BUILD=OFF.
# A new tree is built by Ninja, which compiles a target's sources while the libraries it
# links are still being built (Make waits for them); a tree configured before keeps its
# generator, since CMake refuses to change it.
generator=()
[[ -f "$build_dir/CMakeCache.txt" ]] || generator=(-G Ninja)
cmake "${generator[@]}" -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" \
      -DCMAKE_UNITY_BUILD=ON "-DCMAKE_C_FLAGS_RELEASE=-O2 -DNDEBUG" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
