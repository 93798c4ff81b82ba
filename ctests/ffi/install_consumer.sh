#!/usr/bin/env bash
# The install test: scripts/install.sh into a fresh prefix, then the examples built against the
# installed package as a user would (find_package(SliverMesh CONFIG), static and shared; and
# pkg-config), and run. Exits 77 (skipped) when everything builds but meshing waits on
# refine::mesh ("not implemented yet").
#
#   install_consumer.sh ROOT LIB_DIR WORK_DIR CMAKE C_COMPILER CXX_COMPILER [Fortran_COMPILER]
set -euo pipefail
root="$1" lib_dir="$2" work="$3" cmake="$4" cc="$5" cxx="$6" fc="${7:-}"

rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
"$root/scripts/install.sh" "$prefix" --no-build --lib-dir "$lib_dir"

configure_build() { # name source-dir extra-cmake-args...
  local name="$1" src="$2"
  shift 2
  echo "--- $name: configure and build against $prefix"
  "$cmake" -S "$src" -B "$work/$name" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" ${fc:+-DCMAKE_Fortran_COMPILER="$fc"} \
    "$@" >"$work/$name.configure.log" 2>&1 || { cat "$work/$name.configure.log"; exit 1; }
  "$cmake" --build "$work/$name" >"$work/$name.build.log" 2>&1 || { cat "$work/$name.build.log"; exit 1; }
}

configure_build c-static "$root/examples/c"
configure_build c-shared "$root/examples/c" -DSliverMesh_USE_SHARED=ON
configure_build cpp "$root/examples/cpp"
programs=("$work/c-static/cube_c" "$work/c-shared/cube_c" "$work/cpp/cube_cpp")
if [[ -n "$fc" ]]; then
  configure_build fortran "$root/examples/fortran"
  programs+=("$work/fortran/cube_f")
fi

# The shared build must load the installed library (through its SONAME link).
# (ldd's output is captured first: `ldd | grep -q` under pipefail fails when grep exits early.)
loaded="$(ldd "$work/c-shared/cube_c")"
if ! grep -q "$prefix/lib/libslivermesh.so" <<<"$loaded"; then
  echo "c-shared does not load $prefix/lib/libslivermesh.so:"
  ldd "$work/c-shared/cube_c"
  exit 1
fi

if command -v pkg-config >/dev/null; then
  echo "--- c-pkgconfig: cc \$(pkg-config --cflags --libs slivermesh)"
  export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
  # shellcheck disable=SC2046
  "$cc" -std=c99 -Wall -Wextra -Werror -pedantic "$root/examples/c/cube.c" \
    $(pkg-config --cflags --libs slivermesh) -Wl,-rpath,"$prefix/lib" -lm -o "$work/cube_c_pkgconfig"
  # shellcheck disable=SC2046
  "$cc" -std=c99 "$root/examples/c/cube.c" $(pkg-config --cflags slivermesh) \
    "$prefix/lib/libslivermesh.a" $(pkg-config --static --libs-only-l slivermesh | sed 's/-lslivermesh//') \
    -o "$work/cube_c_pkgconfig_static"
  programs+=("$work/cube_c_pkgconfig" "$work/cube_c_pkgconfig_static")
else
  echo "--- pkg-config not installed: pkg-config check left out"
fi

pending=0
cd "$work"
for p in "${programs[@]}"; do
  echo "--- run $p"
  if out="$("$p" "$(basename "$p").vtu" 2>&1)"; then
    echo "$out"
  elif grep -q "not implemented yet" <<<"$out"; then
    echo "$out"
    pending=1
  else
    echo "$out"
    echo "FAILED: $p"
    exit 1
  fi
done
if ((pending)); then
  echo "SKIP: everything installs, builds and links; meshing waits on refine::mesh"
  exit 77
fi
echo "install test passed"
