#!/bin/sh
# Checks the shipped shared library: exports only sogmm_* symbols, each in
# the version node SOGMM_<ABI> (sogmm_x@@SOGMM_<ABI> in readelf --dyn-syms),
# exports every function the public header declares, has SONAME libsogmm.so.<ABI>,
# and depends dynamically only on the C/C++ runtime and the image decoders
# libpng/libjpeg (no zstd, flatbuffers,
# OpenCV: they must be linked privately and statically).
# Usage: check_library.sh <libsogmm.so> <sogmm.h> <abi-version>
set -eu
lib=$1
header=$2
abi=$3
fail=0

# Defined dynamic symbols as name@@version (readelf, as the spec states the
# rule). The version node itself appears as an absolute symbol SOGMM_<ABI>.
node="SOGMM_$abi"
dynsyms=$(readelf -W --dyn-syms "$lib" | awk '$1 ~ /^[0-9]+:$/ && $7 != "UND" && $5 != "LOCAL" && $8 != "" {print $8}')
exports=$(printf '%s\n' "$dynsyms" | grep -vx "$node" | sed 's/@.*//' | sort -u)
if [ -z "$exports" ]; then echo "no exported symbols in $lib"; exit 1; fi
bad=$(printf '%s\n' "$exports" | grep -v '^sogmm_' || true)
if [ -n "$bad" ]; then
  echo "FAIL: symbols exported outside the sogmm_ prefix:"; printf '%s\n' "$bad" | head -50; fail=1
fi
# Every sogmm_ symbol is in the version node SOGMM_<ABI> as its default version.
unversioned=$(printf '%s\n' "$dynsyms" | grep '^sogmm_' | grep -v "@@$node\$" || true)
if [ -n "$unversioned" ]; then
  echo "FAIL: sogmm_ symbols without the version node $node:"; printf '%s\n' "$unversioned" | head -50; fail=1
fi

# Every SOGMM_API function of the header is exported, and nothing else.
declared=$(tr '\n' ' ' < "$header" | grep -o 'SOGMM_API[^;(]*(' | grep -o 'sogmm_[a-z0-9_]*[[:space:]]*($' |
  sed 's/[[:space:]]*($//' | sort -u)
missing=$(printf '%s\n' "$declared" | while read -r f; do
  printf '%s\n' "$exports" | grep -qx "$f" || echo "$f"; done)
if [ -n "$missing" ]; then echo "FAIL: declared in the header but not exported:"; echo "$missing"; fail=1; fi
extra=$(printf '%s\n' "$exports" | while read -r f; do
  printf '%s\n' "$declared" | grep -qx "$f" || echo "$f"; done)
if [ -n "$extra" ]; then echo "FAIL: exported but not declared in the header:"; echo "$extra"; fail=1; fi

soname=$(readelf -d "$lib" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
if [ "$soname" != "libsogmm.so.$abi" ]; then
  echo "FAIL: SONAME is '$soname', expected libsogmm.so.$abi"; fail=1
fi

needed=$(readelf -d "$lib" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
for n in $needed; do
  case "$n" in
    libstdc++.so.*|libgomp.so.*|libm.so.*|libc.so.*|libgcc_s.so.*|ld-linux*.so.*|libpthread.so.*|libdl.so.*|librt.so.*) ;;
    libasan.so.*|libubsan.so.*|libclang_rt.*) ;;  # sanitizer builds only
    libpng16.so.*|libjpeg.so.*|libz.so.*) ;;  # frame images (format/CMakeLists.txt: no PIC archives to link)
    *) echo "FAIL: unexpected dynamic dependency $n"; fail=1 ;;
  esac
done

count=$(printf '%s\n' "$exports" | wc -l)
if [ $fail -eq 0 ]; then
  echo "OK: $count sogmm_* symbols exported (all declared, all @@$node), SONAME $soname, NEEDED: $(echo $needed)"
fi
exit $fail
