#!/bin/sh
# Runs a ctest command that needs node and the npm packages of bindings/js
# (installed by `npm ci`, which tools/setup.sh runs). Without them the test
# is skipped (exit 77, ctest's SKIP_RETURN_CODE) with a message saying why;
# so is a browser test (SOGMM_CHROMIUM set) when that Chromium is missing.
# Usage: with_node.sh NODE JSDIR COMMAND...
node="$1"; dir="$2"; shift 2
if ! command -v "$node" >/dev/null 2>&1; then
  echo "SKIP: node not found (install nodejs >= 20, then npm ci in bindings/js)"; exit 77
fi
if [ ! -f "$dir/node_modules/zstddec/package.json" ]; then
  echo "SKIP: $dir/node_modules missing: run npm ci in $dir (tools/setup.sh does)"; exit 77
fi
if [ -n "${SOGMM_CHROMIUM:-}" ] && [ ! -x "$SOGMM_CHROMIUM" ]; then
  echo "SKIP: $SOGMM_CHROMIUM not found (apt-get install chromium; tools/setup.sh does)"; exit 77
fi
exec "$@"
