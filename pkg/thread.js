// One thread of the threaded module (gmwm-threads.wasm, wasm32-wasip1-threads): a Web Worker
// that instantiates the module on the shared memory and runs, one after another, the threads
// that `wasi.thread-spawn` hands to its slot (index.js: threadSpawn). Such a thread computes
// (the engine's rayon pool); it has no file descriptors but standard output and error, whose
// progress lines go to the shared progress cell and other lines to the console.
import { WASI, OpenFile, File, ConsoleStdout } from "./vendor/browser_wasi_shim/index.js";
import { threadSpawn, slotState, recordProgress, recordTrap } from "./shared.js";

self.onmessage = async ({ data }) => {
  const { module, memory, control, progress, slot, env } = data;
  const ctl = new Int32Array(control);
  const forward = (line) => {
    // the main worker is busy until the run ends: other lines (a thread's panic message) go to
    // the console
    if (!recordProgress(progress, line)) console.error(line);
  };
  const wasi = new WASI(["gmwm"], env, [
    new OpenFile(new File(new Uint8Array(0), { readonly: true })),
    ConsoleStdout.lineBuffered(forward),
    ConsoleStdout.lineBuffered(forward),
  ], { debug: false });
  const instance = await WebAssembly.instantiate(module, {
    env: { memory },
    wasi: { "thread-spawn": (arg) => threadSpawn(ctl, arg) },
    wasi_snapshot_preview1: wasi.wasiImport,
  });
  wasi.inst = instance;
  self.postMessage({ kind: "ready" });
  const state = slotState(slot);
  for (;;) {
    // 0 idle, 1 being handed a thread, 2 running
    let v;
    while ((v = Atomics.load(ctl, state)) !== 2) Atomics.wait(ctl, state, v);
    const tid = Atomics.load(ctl, state + 1);
    const arg = Atomics.load(ctl, state + 2);
    try {
      instance.exports.wasi_thread_start(tid, arg);
    } catch (e) {
      // a trap (a panic's abort): the process is over; the page stops it
      const message = `a thread of the WebAssembly module stopped: ${e?.message ?? e}`;
      recordTrap(progress, message);
      return;
    }
    Atomics.store(ctl, state, 0);
    Atomics.notify(ctl, state);
  }
};
