#!/usr/bin/env bash
# Builds the release library and installs it for C and C++ hosts under PREFIX:
#   PREFIX/lib/libfraccloth.so, libfraccloth.a
#   PREFIX/include/fraccloth.h, fraccloth.hpp
#   PREFIX/lib/pkgconfig/fraccloth.pc                     (pkg-config --cflags --libs fraccloth)
#   PREFIX/lib/cmake/fraccloth/fraccloth-config.cmake     (find_package(fraccloth); target fraccloth::fraccloth)
#   PREFIX/share/doc/fraccloth/                           (license texts, changelog)
# Usage: bash scripts/install.sh [PREFIX]   (default /usr/local)
set -euo pipefail
cd "$(dirname "$0")/.."
PREFIX="${1:-/usr/local}"
mkdir -p "$PREFIX"
PREFIX="$(cd "$PREFIX" && pwd)"
VERSION="$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
cargo build --release --lib --quiet
install -d "$PREFIX/lib/pkgconfig" "$PREFIX/lib/cmake/fraccloth" "$PREFIX/include"
install -m 644 target/release/libfraccloth.so target/release/libfraccloth.a "$PREFIX/lib/"
install -m 644 include/fraccloth.h bindings/cpp/fraccloth.hpp "$PREFIX/include/"
sed -e "s|@PREFIX@|$PREFIX|g" -e "s|@VERSION@|$VERSION|g" packaging/fraccloth.pc.in > "$PREFIX/lib/pkgconfig/fraccloth.pc"
sed -e "s|@VERSION@|$VERSION|g" packaging/fraccloth-config-version.cmake.in > "$PREFIX/lib/cmake/fraccloth/fraccloth-config-version.cmake"
install -m 644 packaging/fraccloth-config.cmake "$PREFIX/lib/cmake/fraccloth/"
install -d "$PREFIX/share/doc/fraccloth"
install -m 644 LICENSE-MIT LICENSE-APACHE CHANGELOG.md "$PREFIX/share/doc/fraccloth/"
echo "installed fraccloth $VERSION under $PREFIX"
