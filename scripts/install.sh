#!/usr/bin/env bash
# Installs fraccloth for C and C++ hosts, as a distribution packager expects:
#   LIBDIR/libfraccloth.so.X.Y.Z              stripped, mode 755; SONAME libfraccloth.so.X
#   LIBDIR/libfraccloth.so.X -> .so.X.Y.Z     the loader's name for it
#   LIBDIR/libfraccloth.so   -> .so.X         the linker's name for it (-lfraccloth)
#   LIBDIR/libfraccloth.a                     one object; only the fc_* symbols are global
#   PREFIX/include/fraccloth.h, fraccloth.hpp
#   LIBDIR/pkgconfig/fraccloth.pc             pkg-config --cflags --libs [--static] fraccloth
#   LIBDIR/cmake/fraccloth/                   find_package(fraccloth): fraccloth::fraccloth
#                                             (shared) and fraccloth::fraccloth_static
#   PREFIX/share/doc/fraccloth/               license texts, changelog
#   PREFIX/share/fraccloth/install_manifest.txt   what --uninstall removes
# LIBDIR is chosen as CMake's GNUInstallDirs does: lib/<multiarch> on Debian for PREFIX=/usr,
# lib64 on other 64-bit Linux systems (not Arch, not Alpine), lib otherwise; LIBDIR=... overrides
# (relative to PREFIX). DESTDIR stages the files for a package (paths inside them stay PREFIX).
#
# Usage: bash scripts/install.sh [PREFIX]              (default /usr/local)
#        bash scripts/install.sh --uninstall [PREFIX]  removes what the install wrote
#        bash scripts/install.sh --print-libdir [PREFIX]
set -euo pipefail
cd "$(dirname "$0")/.."

mode=install
case "${1:-}" in
  --uninstall) mode=uninstall; shift ;;
  --print-libdir) mode=print; shift ;;
esac
PREFIX="${1:-/usr/local}"
case "$PREFIX" in /*) ;; *) PREFIX="$(pwd)/$PREFIX" ;; esac
PREFIX="${PREFIX%/}"
[ -n "$PREFIX" ] || PREFIX=/
DESTDIR="${DESTDIR:-}"
ROOT="$DESTDIR$PREFIX"
MANIFEST_REL="share/fraccloth/install_manifest.txt"

gnu_libdir() {
  if [ "$(uname -s)" = Linux ] && [ ! -e /etc/arch-release ] && [ ! -e /etc/alpine-release ]; then
    if [ -e /etc/debian_version ]; then
      if [ "$PREFIX" = /usr ]; then
        local arch
        arch="$(cc -print-multiarch 2>/dev/null || dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || true)"
        if [ -n "$arch" ]; then echo "lib/$arch"; return; fi
      fi
    elif [ "$(getconf LONG_BIT 2>/dev/null || echo 64)" = 64 ]; then
      echo lib64; return
    fi
  fi
  echo lib
}
LIBDIR="${LIBDIR:-$(gnu_libdir)}"
LIBDIR="${LIBDIR#"$PREFIX"/}"

if [ "$mode" = print ]; then echo "$PREFIX/$LIBDIR"; exit 0; fi

if [ "$mode" = uninstall ]; then
  manifest="$ROOT/$MANIFEST_REL"
  [ -f "$manifest" ] || { echo "no $manifest: nothing installed by scripts/install.sh under $ROOT" >&2; exit 1; }
  while IFS= read -r f; do
    rm -f "$ROOT/$f"
  done < "$manifest"
  rm -f "$manifest"
  # Remove the directories the install made, if now empty (never PREFIX itself).
  for d in "$LIBDIR/cmake/fraccloth" "$LIBDIR/pkgconfig" "$LIBDIR/cmake" share/doc/fraccloth share/fraccloth share/doc share include "$LIBDIR" lib; do
    rmdir "$ROOT/$d" 2>/dev/null || true
  done
  echo "uninstalled fraccloth from $ROOT"
  exit 0
fi

VERSION="$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
MAJOR="${VERSION%%.*}"
cargo build --release --lib --quiet
for tool in strip objcopy ld ar readelf; do
  command -v "$tool" >/dev/null || { echo "install.sh needs $tool (binutils)" >&2; exit 1; }
done

L="$ROOT/$LIBDIR"
install -d "$L/pkgconfig" "$L/cmake/fraccloth" "$ROOT/include" "$ROOT/share/doc/fraccloth" "$ROOT/share/fraccloth"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Shared library: stripped of debug information and local symbols, executable, versioned links.
install -m 755 target/release/libfraccloth.so "$L/libfraccloth.so.$VERSION"
strip --strip-unneeded "$L/libfraccloth.so.$VERSION"
ln -sfn "libfraccloth.so.$VERSION" "$L/libfraccloth.so.$MAJOR"
ln -sfn "libfraccloth.so.$MAJOR" "$L/libfraccloth.so"

# Static library: the Rust runtime and crates inside it would export thousands of symbols that
# clash with another Rust static library in the same host. Link it into one relocatable object,
# keep only fc_* global, drop debug information, and archive that.
ld -r --whole-archive target/release/libfraccloth.a -o "$work/fraccloth.o"
# readelf, not nm: nm's LTO plugin chokes on the LLVM bitcode rustc embeds in its objects.
readelf -sW "$work/fraccloth.o" | awk '$5 == "GLOBAL" && $7 != "UND" && $8 ~ /^fc_/ {print $8}' | sort -u > "$work/keep.txt"
[ -s "$work/keep.txt" ] || { echo "no fc_* symbols in the static library" >&2; exit 1; }
objcopy --strip-debug --remove-section=.llvmbc --remove-section=.llvmcmd \
  --keep-global-symbols="$work/keep.txt" "$work/fraccloth.o"
rm -f "$work/libfraccloth.a"
ar rcs "$work/libfraccloth.a" "$work/fraccloth.o"
install -m 644 "$work/libfraccloth.a" "$L/"

install -m 644 include/fraccloth.h bindings/cpp/fraccloth.hpp "$ROOT/include/"
sed -e "s|@PREFIX@|$PREFIX|g" -e "s|@LIBDIR@|$LIBDIR|g" -e "s|@VERSION@|$VERSION|g" \
  packaging/fraccloth.pc.in > "$work/fraccloth.pc"
install -m 644 "$work/fraccloth.pc" "$L/pkgconfig/"
# The CMake package finds the prefix from its own location: as many ".." as LIBDIR is deep, plus
# two for cmake/fraccloth.
up="$(echo "$LIBDIR/cmake/fraccloth" | sed 's|[^/][^/]*|..|g')"
sed -e "s|@VERSION@|$VERSION|g" packaging/fraccloth-config-version.cmake.in > "$work/fraccloth-config-version.cmake"
sed -e "s|@UP@|$up|g" -e "s|@LIBDIR@|$LIBDIR|g" -e "s|@VERSION@|$VERSION|g" -e "s|@MAJOR@|$MAJOR|g" \
  packaging/fraccloth-config.cmake.in > "$work/fraccloth-config.cmake"
install -m 644 "$work/fraccloth-config.cmake" "$work/fraccloth-config-version.cmake" "$L/cmake/fraccloth/"
install -m 644 LICENSE-MIT LICENSE-APACHE CHANGELOG.md "$ROOT/share/doc/fraccloth/"

cat > "$ROOT/$MANIFEST_REL" <<MANIFEST
$LIBDIR/libfraccloth.so.$VERSION
$LIBDIR/libfraccloth.so.$MAJOR
$LIBDIR/libfraccloth.so
$LIBDIR/libfraccloth.a
include/fraccloth.h
include/fraccloth.hpp
$LIBDIR/pkgconfig/fraccloth.pc
$LIBDIR/cmake/fraccloth/fraccloth-config.cmake
$LIBDIR/cmake/fraccloth/fraccloth-config-version.cmake
share/doc/fraccloth/LICENSE-MIT
share/doc/fraccloth/LICENSE-APACHE
share/doc/fraccloth/CHANGELOG.md
MANIFEST
chmod 644 "$ROOT/$MANIFEST_REL"
echo "installed fraccloth $VERSION under $ROOT (libdir $PREFIX/$LIBDIR)"
case "$PREFIX/$LIBDIR" in
  /usr/lib*|/usr/local/lib*|/lib*) echo "run ldconfig (as root) so the loader sees the new library" ;;
  *) echo "the loader does not search $PREFIX/$LIBDIR: link with -Wl,-rpath,$PREFIX/$LIBDIR or set LD_LIBRARY_PATH" ;;
esac
