#!/usr/bin/env bash
# ctest install.external: installs the build into a temporary prefix, then configures, builds and
# runs tests/install/external against it, once through find_package(lacuna CONFIG) and once
# through pkg-config (--static: the library and everything it links).
# Usage: install_test.sh BUILD_DIR SOURCE_DIR CXX [CXXFLAGS [LDFLAGS]] (the build's own flags:
# a sanitizer build's library needs its runtime in the program as well).
set -euo pipefail
build=$1 src=$2 cxx=$3 cxxflags=${4:-} ldflags=${5:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
# 1. CMake package.
cmake -S "$src/tests/install/external" -B "$tmp/ext" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
      -DCMAKE_CXX_FLAGS="$cxxflags" -DCMAKE_EXE_LINKER_FLAGS="$ldflags" >/dev/null
cmake --build "$tmp/ext" >/dev/null
"$tmp/ext/render_sphere" "$tmp/cmake.png"
# 2. pkg-config.
pc=$(find "$tmp/prefix" -name lacuna.pc)
flags=$(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --cflags --libs --static lacuna)
# shellcheck disable=SC2086  # the flags are words
"$cxx" -O1 $cxxflags "$src/tests/install/external/render_sphere.cpp" -o "$tmp/render_pc" $flags $ldflags
"$tmp/render_pc" "$tmp/pc.png"
cmp "$tmp/cmake.png" "$tmp/pc.png"
echo "install.external: the CMake package and pkg-config both build and render"
