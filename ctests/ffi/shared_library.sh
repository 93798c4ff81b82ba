#!/usr/bin/env bash
# The shared library as a distribution would package it: scripts/install.sh into a fresh prefix,
# then check
#  - PREFIX/lib holds libslivermesh.so.MAJOR.MINOR.PATCH, the SONAME link to it and the
#    unversioned link to the SONAME link, and `objdump -p` shows the SONAME;
#  - `nm -D --defined-only` lists only sm_* symbols;
#  - the CMake version file accepts exactly the compatible requests (same minor for 0.x);
#  - a consumer linked with -lslivermesh records the SONAME, and still runs once the unversioned
#    libslivermesh.so link is gone (as on a system with only the runtime package).
#
#   shared_library.sh ROOT LIB_DIR WORK_DIR CMAKE C_COMPILER
set -euo pipefail
root="$1" lib_dir="$2" work="$3" cmake="$4" cc="$5"
fail() { echo "FAIL: $*"; exit 1; }

rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
"$root/scripts/install.sh" "$prefix" --no-build --lib-dir "$lib_dir"
version="$(sed -n 's/^version *= *"\([^"]*\)".*/\1/p' "$root/Cargo.toml" | head -n 1)"
IFS=. read -r major minor patch <<<"$version"
if [[ "$major" == 0 ]]; then soname="libslivermesh.so.0.$minor"; else soname="libslivermesh.so.$major"; fi
real="libslivermesh.so.$major.$minor.$patch"
lib="$prefix/lib"

echo "--- files in $lib"
ls -l "$lib" | grep libslivermesh
[[ -f "$lib/$real" && ! -L "$lib/$real" ]] || fail "$lib/$real is not a regular file"
[[ "$(readlink "$lib/$soname")" == "$real" ]] || fail "$soname does not link to $real"
[[ "$(readlink "$lib/libslivermesh.so")" == "$soname" ]] || fail "libslivermesh.so does not link to $soname"

echo "--- objdump -p $real | grep SONAME"
found="$(objdump -p "$lib/$real" | sed -n 's/^ *SONAME *//p')"
echo "SONAME $found"
[[ "$found" == "$soname" ]] || fail "SONAME is '${found:-none}', expected $soname"

echo "--- nm -D --defined-only $real"
symbols="$(nm -D --defined-only "$lib/$real" | awk '{print $NF}')"
count="$(wc -l <<<"$symbols")"
others="$(grep -v '^sm_' <<<"$symbols" || true)"
echo "$count defined dynamic symbols"
[[ -z "$others" ]] || fail "exported symbols without the sm_ prefix: $(tr '\n' ' ' <<<"$others")"
grep -qx sm_version <<<"$symbols" || fail "sm_version is not exported"

echo "--- CMake version file (compatible: same major and, for 0.x, same minor; not older)"
cat >"$work/version_check.cmake" <<CMAKE
set(CMAKE_SIZEOF_VOID_P 8)
foreach(req IN LISTS REQUESTS)
  string(REPLACE ":" ";" pair "\${req}")
  list(GET pair 0 want)
  list(GET pair 1 expect)
  set(PACKAGE_FIND_VERSION "\${want}")
  string(REGEX MATCHALL "[0-9]+" parts "\${want}")
  list(GET parts 0 PACKAGE_FIND_VERSION_MAJOR)
  list(GET parts 1 PACKAGE_FIND_VERSION_MINOR)
  unset(PACKAGE_VERSION_COMPATIBLE)
  include("$lib/cmake/SliverMesh/SliverMeshConfigVersion.cmake")
  if(PACKAGE_VERSION_COMPATIBLE)
    set(got yes)
  else()
    set(got no)
  endif()
  message(STATUS "find_package(SliverMesh \${want}) with \${PACKAGE_VERSION}: compatible \${got}")
  if(NOT got STREQUAL expect)
    message(FATAL_ERROR "find_package(SliverMesh \${want}): expected compatible=\${expect}")
  endif()
endforeach()
CMAKE
next_minor="$major.$((minor + 1)).0"
if [[ "$major" == 0 ]]; then
  requests="$major.$minor:yes;$major.$minor.$patch:yes;$major.$((minor + 1)):no;$((major + 1)).0:no"
  ((minor == 0)) || requests="$requests;$major.$((minor - 1)):no"
else
  requests="$major.$minor:yes;$major.0:yes;$next_minor:no;$((major + 1)).0:no"
fi
"$cmake" -DREQUESTS="$requests" -P "$work/version_check.cmake"

echo "--- consumer: cc version_consumer.c -L$lib -lslivermesh"
"$cc" -std=c99 -Wall -Wextra -Werror -pedantic -I"$prefix/include" \
  "$root/ctests/ffi/version_consumer.c" -L"$lib" -lslivermesh -Wl,-rpath,"$lib" \
  -o "$work/version_consumer"
needed="$(objdump -p "$work/version_consumer" | sed -n 's/^ *NEEDED *\(libslivermesh.*\)/\1/p')"
echo "NEEDED $needed"
[[ "$needed" == "$soname" ]] || fail "the consumer needs '$needed', expected $soname"
"$work/version_consumer"
rm "$lib/libslivermesh.so"
echo "--- removed $lib/libslivermesh.so; the consumer still runs:"
"$work/version_consumer"
echo "shared library checks passed"
