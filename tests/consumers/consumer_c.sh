#!/usr/bin/env bash
# ctest consumer_c: a C program in a folder outside the repository, built
# against this build five ways, each run with no environment variables:
# the installed prefix via pkg-config, via find_package (the program itself
# installed too, which drops CMake's build rpath) and via libsogmm.a (whose
# only strong globals must be sogmm_*), and the build tree via pkg-config and
# via -Dsogmm_DIR. Usage: consumer_c.sh <build> <source> <cmake> <generator>
. "$(dirname "$0")/common.sh"
cmake=$3 generator=$4
cp -r "$SRC/tests/consumers/c" "$work/src"
"$cmake" --install "$BUILD" --prefix "$work/prefix" --component sogmm_capi >/dev/null
pcdir=$(dirname "$(find "$work/prefix" -name sogmm.pc)")
libdir=$(dirname "$(find "$work/prefix" -name libsogmm.so.2)")

compile_pc() { # <PKG_CONFIG_PATH> <output>
  clean PKG_CONFIG_PATH="$1" sh -c \
    'cc -std=c99 -Wall -Wextra -pedantic -Werror "$0" $(pkg-config --cflags --libs sogmm) -lm -o "$1"' \
    "$work/src/consumer.c" "$2"
}
configure() { # <folder> <cmake arguments...>
  local dir=$1; shift
  clean "$cmake" -S "$work/src" -B "$dir" -G "$generator" "$@" >/dev/null
  clean "$cmake" --build "$dir" >/dev/null
}

echo "== installed, pkg-config"
compile_pc "$pcdir" "$work/pc-installed"
check_runs "$work/pc-installed" "$libdir"

echo "== installed, find_package, program installed"
configure "$work/cmake-installed" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_INSTALL_PREFIX="$work/app"
clean "$cmake" --install "$work/cmake-installed" >/dev/null
check_runs "$work/app/bin/consumer" "$libdir"

echo "== build tree, pkg-config"
compile_pc "$BUILD/capi" "$work/pc-build"
check_runs "$work/pc-build" "$BUILD/capi"

echo "== build tree, find_package"
configure "$work/cmake-build" -Dsogmm_DIR="$BUILD/capi"
check_runs "$work/cmake-build/consumer" "$BUILD/capi"

echo "== installed, static archive"
leaked=$(nm -g --defined-only "$libdir/libsogmm.a" | awk '$2 ~ /^[TDBRC]$/ && $3 !~ /^sogmm_/ {print $3}')
if [ -n "$leaked" ]; then
  echo "FAIL: libsogmm.a exports more than sogmm_*: $(echo "$leaked" | head -5)" >&2; exit 1
fi
clean cc -std=c99 -Wall -Wextra -pedantic -Werror "$work/src/consumer.c" -I"$work/prefix/include" \
  "$libdir/libsogmm.a" -lstdc++ -lgomp -lpng16 -ljpeg -lm -o "$work/static-installed"
check_runs "$work/static-installed" static
