// The page's calibration runs here, off the main thread: the page stays responsive and shows
// the progress this worker posts. One message in ({bytes, name, sidecar, options}), progress
// messages out, then one result or one error.
import { calibrateAll, GmwmError } from "./pkg/index.js";

self.onmessage = async (event) => {
  const { bytes, name, sidecar, options } = event.data;
  try {
    const result = await calibrateAll(bytes, {
      ...options,
      name,
      sidecar,
      onProgress: (progress) => self.postMessage({ kind: "progress", progress }),
    });
    self.postMessage({ kind: "done", result });
  } catch (e) {
    const line = e instanceof GmwmError ? e.message : `${e?.message ?? e}`;
    self.postMessage({ kind: "error", line, stderr: e?.stderr ?? "" });
  }
};
