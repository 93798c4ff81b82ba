#!/usr/bin/env bash
# Installs the slivermesh C ABI into a prefix:
#
#   scripts/install.sh PREFIX                 # cargo build --release --lib, then install
#   scripts/install.sh PREFIX --no-build      # install what target/release already holds
#   scripts/install.sh PREFIX --lib-dir DIR   # take the libraries from DIR (e.g. target/debug)
#
# Installs
#   PREFIX/lib/libslivermesh.so.MAJOR.MINOR.PATCH   (the shared library; its SONAME is
#                                          libslivermesh.so.0.MINOR for 0.x, .so.MAJOR from 1.0)
#   PREFIX/lib/libslivermesh.so.0.MINOR -> it     (the SONAME link, what programs load)
#   PREFIX/lib/libslivermesh.so -> the SONAME link (for linking with -lslivermesh)
#   PREFIX/lib/libslivermesh.a
#   PREFIX/include/slivermesh.h            (the C/C++ header)
#   PREFIX/include/slivermesh.f90          (the Fortran interface module, as source)
#   PREFIX/lib/cmake/SliverMesh/SliverMeshConfig.cmake, SliverMeshConfigVersion.cmake
#                                          (find_package(SliverMesh CONFIG): SliverMesh::slivermesh)
#   PREFIX/lib/pkgconfig/slivermesh.pc     (pkg-config --cflags --libs slivermesh)
# Consumers: cmake -DCMAKE_PREFIX_PATH=PREFIX, or PKG_CONFIG_PATH=PREFIX/lib/pkgconfig.
set -euo pipefail

usage() {
  sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
prefix=""
build=1
lib_dir=""
while (($#)); do
  case "$1" in
    --no-build) build=0 ;;
    --lib-dir)
      (($# >= 2)) || usage
      lib_dir="$2"
      shift
      ;;
    -h | --help) usage ;;
    -*) echo "install.sh: unknown option $1" >&2; usage ;;
    *)
      [[ -z "$prefix" ]] || usage
      prefix="$1"
      ;;
  esac
  shift
done
[[ -n "$prefix" ]] || usage

if [[ -z "$lib_dir" ]]; then
  lib_dir="${CARGO_TARGET_DIR:-$root/target}/release"
  if ((build)); then
    (cd "$root" && cargo build --release --lib)
  fi
fi

for f in "$lib_dir/libslivermesh.so" "$lib_dir/libslivermesh.a" "$root/include/slivermesh.h" \
  "$root/include/slivermesh.f90"; do
  if [[ ! -f "$f" ]]; then
    echo "install.sh: missing $f (build with: cargo build --release --lib)" >&2
    exit 1
  fi
done

version="$(sed -n 's/^version *= *"\([^"]*\)".*/\1/p' "$root/Cargo.toml" | head -n 1)"
[[ -n "$version" ]] || { echo "install.sh: no version in Cargo.toml" >&2; exit 1; }
sizeof_void_p="$(getconf LONG_BIT 2>/dev/null || echo 64)"
sizeof_void_p=$((sizeof_void_p / 8))

# The SONAME rule of build.rs; the library must carry it (an older build has none).
IFS=. read -r major minor _ <<<"$version"
if [[ "$major" == 0 ]]; then soname="libslivermesh.so.0.$minor"; else soname="libslivermesh.so.$major"; fi
real="libslivermesh.so.${version%%[-+]*}"
if command -v objdump >/dev/null; then
  found="$(objdump -p "$lib_dir/libslivermesh.so" | sed -n 's/^ *SONAME *//p')"
  if [[ "$found" != "$soname" ]]; then
    echo "install.sh: $lib_dir/libslivermesh.so has SONAME '${found:-none}', expected $soname" \
      "(rebuild with: cargo build --release --lib)" >&2
    exit 1
  fi
fi

mkdir -p "$prefix"
prefix="$(cd "$prefix" && pwd)"
cmake_dir="$prefix/lib/cmake/SliverMesh"
install -d "$prefix/lib" "$prefix/include" "$cmake_dir" "$prefix/lib/pkgconfig"
rm -f "$prefix/lib/libslivermesh.so" "$prefix/lib/$soname"
install -m 755 "$lib_dir/libslivermesh.so" "$prefix/lib/$real"
ln -s "$real" "$prefix/lib/$soname"
ln -s "$soname" "$prefix/lib/libslivermesh.so"
install -m 644 "$lib_dir/libslivermesh.a" "$prefix/lib/"
install -m 644 "$root/include/slivermesh.h" "$root/include/slivermesh.f90" "$prefix/include/"
sed -e "s|@SLIVERMESH_SONAME@|$soname|g" -e "s|@SLIVERMESH_LIBRARY@|$real|g" \
  "$root/cmake/SliverMeshConfig.cmake.in" >"$cmake_dir/SliverMeshConfig.cmake"
sed -e "s|@SLIVERMESH_VERSION@|$version|g" -e "s|@SLIVERMESH_SIZEOF_VOID_P@|$sizeof_void_p|g" \
  "$root/cmake/SliverMeshConfigVersion.cmake.in" >"$cmake_dir/SliverMeshConfigVersion.cmake"
sed -e "s|@PREFIX@|$prefix|g" -e "s|@SLIVERMESH_VERSION@|$version|g" \
  "$root/cmake/slivermesh.pc.in" >"$prefix/lib/pkgconfig/slivermesh.pc"

echo "installed slivermesh $version into $prefix (libraries from $lib_dir)"
