// The page's calibration runs here, off the main thread: the page stays responsive and shows
// the progress this worker posts. One message in ({bytes, name, sidecar, options}), progress
// messages out, then one result or one error. With threads (a cross-origin isolated page),
// the engine's pool runs on further workers and the page reads their progress from a shared
// cell, since this worker is busy until the calibration ends.
import { calibrateAll, GmwmError, availableThreads, progressCell } from "./pkg/index.js";

self.onmessage = async (event) => {
  const { bytes, name, sidecar, options } = event.data;
  const threads = options.threads === "auto" || options.threads === undefined
    ? availableThreads()
    : Math.min(Number(options.threads), availableThreads());
  const cell = typeof SharedArrayBuffer !== "undefined" ? progressCell() : undefined;
  self.postMessage({ kind: "started", threads, cell });
  try {
    const result = await calibrateAll(bytes, {
      ...options,
      name,
      sidecar,
      threads,
      progressCell: cell,
      onProgress: (progress) => self.postMessage({ kind: "progress", progress }),
    });
    self.postMessage({ kind: "done", result: { ...result, threads } });
  } catch (e) {
    const line = e instanceof GmwmError ? e.message : `${e?.message ?? e}`;
    self.postMessage({ kind: "error", line, stderr: e?.stderr ?? "" });
  }
};
