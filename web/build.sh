#!/usr/bin/env bash
# Builds the browser page and the npm-style package, in one command:
#
#   web/build.sh
#
# 1. the gmwm command (crates/gmwm-cli) for WebAssembly (wasm32-wasip1, a WASI program; without
#    SQLite, whose C sources need a WebAssembly C compiler: a rosbag2 .db3 file is refused in
#    one line) -> pkg/gmwm.wasm
# 2. the WASI shim that runs it in a browser or Node.js (@bjorn3/browser_wasi_shim from the npm
#    registry, pinned, MIT/Apache-2.0) -> pkg/vendor/browser_wasi_shim/
#    and the same with threads (wasm32-wasip1-threads) -> pkg/gmwm-threads.wasm
# 3. the static page: web/index.html, app.js, worker.js and the package -> web/dist/, servable
#    from any static host; web/serve.py serves it cross-origin isolated (threads)
set -euo pipefail
cd "$(dirname "$0")/.."
SHIM_VERSION=0.4.2

rustup target add wasm32-wasip1 >/dev/null 2>&1 || true
cargo build --release --locked --target wasm32-wasip1 -p gmwm-cli --no-default-features
cp target/wasm32-wasip1/release/gmwm.wasm pkg/gmwm.wasm
# the threaded module (wasi-threads: the engine's rayon pool on Web Workers sharing its memory,
# where the page is cross-origin isolated), its shared memory allowed to grow to 4 GiB
rustup target add wasm32-wasip1-threads >/dev/null 2>&1 || true
CARGO_TARGET_WASM32_WASIP1_THREADS_RUSTFLAGS="-C link-arg=--max-memory=4294967296" \
  cargo build --release --locked --target wasm32-wasip1-threads -p gmwm-cli --no-default-features
cp target/wasm32-wasip1-threads/release/gmwm.wasm pkg/gmwm-threads.wasm

npm_dir=target/web-npm
if [ ! -f "$npm_dir/node_modules/@bjorn3/browser_wasi_shim/package.json" ] ||
   ! grep -q "\"version\": \"$SHIM_VERSION\"" "$npm_dir/node_modules/@bjorn3/browser_wasi_shim/package.json"; then
  mkdir -p "$npm_dir"
  npm install --silent --no-audit --no-fund --prefix "$npm_dir" "@bjorn3/browser_wasi_shim@$SHIM_VERSION"
fi
shim="$npm_dir/node_modules/@bjorn3/browser_wasi_shim"
rm -rf pkg/vendor
mkdir -p pkg/vendor/browser_wasi_shim
cp "$shim"/dist/*.js "$shim"/package.json pkg/vendor/browser_wasi_shim/
cp "$shim"/LICENSE* pkg/vendor/browser_wasi_shim/ 2>/dev/null || true

rm -rf web/dist
mkdir -p web/dist/pkg
cp web/index.html web/app.js web/worker.js web/dist/
cp -r pkg/index.js pkg/shared.js pkg/thread.js pkg/package.json pkg/gmwm.wasm pkg/gmwm-threads.wasm \
  pkg/vendor web/dist/pkg/
echo "web/dist: $(du -sh web/dist | cut -f1) (gmwm.wasm $(( $(stat -c %s pkg/gmwm.wasm) / 1024 )) KiB, gmwm-threads.wasm $(( $(stat -c %s pkg/gmwm-threads.wasm) / 1024 )) KiB); pkg/ ready"
