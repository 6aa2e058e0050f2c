// gmwm in WebAssembly: the `gmwm` command (crates/gmwm-cli, built for wasm32-wasip1 by
// web/build.sh) run on an in-memory file system, in a browser (a page or a Web Worker) or in
// Node.js. Nothing leaves the machine: the recording's bytes go into the module's memory and the
// results come back as bytes.
//
//   import { calibrate } from "gmwm-wasm";
//   const doc = await calibrate(bytes, { name: "imu.csv.gz", sidecar: sidecarText });
//   doc.axes[0].noise_density.value   // rad/s/√Hz, as `gmwm calibrate --json`
//
// The numbers are the command's: the same engine, the same defaults, the same one-line errors.
import {
  WASI,
  File,
  OpenFile,
  ConsoleStdout,
  PreopenDirectory,
  Directory,
} from "./vendor/browser_wasi_shim/index.js";
import { controlBlock, threadSpawn, progressCell, recordProgress, parseProgress } from "./shared.js";

export { progressCell, readProgress } from "./shared.js";

/** The error of a run that failed: `message` is gmwm's one line (without `gmwm: error: `). */
export class GmwmError extends Error {
  constructor(message, { code, stderr } = {}) {
    super(message);
    this.name = "GmwmError";
    /** Exit status of the command (1: input or computation, 2: usage). */
    this.code = code;
    /** Everything the command wrote on standard error. */
    this.stderr = stderr;
  }
}

/** The export formats of `--export` (Kalibr has its own flag): stack name -> file name. */
export const EXPORTS = {
  kalibr: "kalibr_imu.yaml",
  openvins: "openvins_imu.yaml",
  vins: "vins_imu.yaml",
  orbslam3: "orbslam3_imu.yaml",
  px4: "px4_imu.params",
};

const compiled = new Map();

/**
 * Threads this context can run the engine on: `navigator.hardwareConcurrency` where
 * SharedArrayBuffer and Web Workers are available (a page served cross-origin isolated:
 * `Cross-Origin-Opener-Policy: same-origin` and `Cross-Origin-Embedder-Policy: require-corp`),
 * else 1. Node.js runs one thread (its workers are not Web Workers).
 */
export function availableThreads() {
  if (typeof SharedArrayBuffer === "undefined" || typeof Worker === "undefined") return 1;
  if (globalThis.crossOriginIsolated !== true) return 1;
  return Math.max(1, Math.min(16, globalThis.navigator?.hardwareConcurrency ?? 1));
}

/**
 * The compiled module (compiled once per realm): `options.module` (a WebAssembly.Module),
 * else `gmwm.wasm` (one thread) or `gmwm-threads.wasm` (`options.threads` > 1) beside this
 * file, fetched in a browser or read from disk in Node.js.
 */
export async function loadModule(options = {}) {
  if (options.module) return options.module;
  const file = (options.threads ?? 1) > 1 ? "gmwm-threads.wasm" : "gmwm.wasm";
  if (!compiled.has(file)) {
    compiled.set(file, (async () => {
      const url = new URL(`./${file}`, import.meta.url);
      if (url.protocol === "file:" && typeof process !== "undefined" && process.versions?.node) {
        const { readFile } = await import("node:fs/promises");
        return WebAssembly.compile(await readFile(url));
      }
      const response = await fetch(url);
      if (!response.ok) throw new GmwmError(`${url}: HTTP ${response.status}`);
      try {
        // streaming compilation needs the server to say application/wasm
        return await WebAssembly.compileStreaming(response.clone());
      } catch {
        return WebAssembly.compile(await response.arrayBuffer());
      }
    })());
  }
  return compiled.get(file);
}

function bytesOf(data) {
  if (data instanceof Uint8Array) return data;
  if (data instanceof ArrayBuffer) return new Uint8Array(data);
  if (ArrayBuffer.isView(data)) return new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  if (typeof data === "string") return new TextEncoder().encode(data);
  if (data && typeof data === "object") return new TextEncoder().encode(JSON.stringify(data));
  throw new TypeError("a file's content must be bytes, a string or a JSON object");
}

/** A file name without folders (the page's and the package's files live in one folder). */
function baseName(name) {
  const base = String(name).split(/[\\/]/).pop();
  if (!base || base === "." || base === "..") throw new GmwmError(`"${name}" is not a file name`);
  return base;
}

/**
 * Runs `gmwm ARGS...` once, with `files` (name -> bytes) in the working folder `/work`, and
 * returns what it did.
 *
 * @param {string[]} args  the command line after `gmwm`; paths are relative to `/work`
 * @param {object} [options]
 * @param {Object<string, Uint8Array|ArrayBuffer|string>} [options.files]  input files
 * @param {(p: {message: string, done: number, total: number, unit: string}) => void} [options.onProgress]
 * @param {(line: string) => void} [options.onStderr]  every other line of standard error
 * @param {WebAssembly.Module} [options.module]
 * @param {number} [options.threads]  engine threads (default {@link availableThreads}); more
 *   than one runs `gmwm-threads.wasm` on Web Workers sharing its memory
 * @param {SharedArrayBuffer} [options.progressCell]  a {@link progressCell} that every
 *   thread's progress updates (read it with `readProgress` from another thread)
 * @returns {Promise<{code: number, stdout: string, stderr: string, files: Map<string, Uint8Array>, memoryBytes: number, seconds: number}>}
 *   `files`: every file in `/work` after the run (inputs included), `memoryBytes`: the
 *   module's memory at the end (its peak: WebAssembly memory only grows)
 */
export async function run(args, options = {}) {
  const threads = Math.max(1, Math.floor(options.threads ?? availableThreads()));
  if (threads > 1 && availableThreads() === 1) {
    throw new GmwmError(`${threads} threads need SharedArrayBuffer and Web Workers (a page served with the cross-origin isolation headers); this context has none`);
  }
  const module = await loadModule({ ...options, threads });
  const contents = new Map();
  for (const [name, data] of Object.entries(options.files ?? {})) {
    contents.set(baseName(name), new File(bytesOf(data), { readonly: true }));
  }
  const work = new PreopenDirectory("/", contents);
  const tmp = new PreopenDirectory("/tmp", new Map());
  const out = [];
  const err = [];
  const stdout = ConsoleStdout.lineBuffered((line) => out.push(line));
  const cell = options.progressCell ?? (threads > 1 ? progressCell() : null);
  const stderr = ConsoleStdout.lineBuffered((line) => {
    const progress = parseProgress(line);
    if (progress) {
      if (cell) recordProgress(cell, line);
      options.onProgress?.(progress);
      return;
    }
    err.push(line);
    options.onStderr?.(line);
  });
  const stdin = new OpenFile(new File(new Uint8Array(0), { readonly: true }));
  const env = ["GMWM_PROGRESS=lines", "TMPDIR=/tmp", "NO_COLOR=1", "TERM=dumb"];
  if (threads > 1) env.push(`RAYON_NUM_THREADS=${threads}`);
  const wasi = new WASI(["gmwm", ...args], env, [stdin, stdout, stderr, work, tmp], { debug: false });
  const imports = { wasi_snapshot_preview1: wasi.wasiImport };
  let pool = null;
  let memory = null;
  let control = null;
  if (threads > 1) {
    memory = new WebAssembly.Memory({ ...SHARED_PAGES, shared: true });
    // two more workers than the pool's threads, for threads the program starts besides it
    control = controlBlock(threads + 2);
    imports.env = { memory };
    imports.wasi = { "thread-spawn": (arg) => threadSpawn(control, arg) };
  }
  // the main instance first: the first instance on a shared memory initialises it and the
  // main thread's thread-local storage (an instance made before would leave the main thread's
  // TLS uninitialised: "cannot access a Thread Local Storage value")
  const instance = await WebAssembly.instantiate(module, imports);
  if (threads > 1) pool = await threadPool(module, memory, control, cell, env);
  const started = performance.now();
  let code;
  try {
    code = wasi.start(instance);
  } catch (e) {
    // a trap (out of memory, an abort after a panic): gmwm's own line, if it wrote one, is in
    // err; the trap's message otherwise
    code = 101;
    err.push(`gmwm: error: the WebAssembly module stopped: ${e?.message ?? e}`);
  } finally {
    pool?.workers.forEach((w) => w.terminate());
  }
  const seconds = (performance.now() - started) / 1000;
  const files = new Map();
  collect(work.dir, "", files);
  return {
    code,
    stdout: out.join("\n") + (out.length ? "\n" : ""),
    stderr: err.join("\n") + (err.length ? "\n" : ""),
    files,
    memoryBytes: instance.exports.memory.buffer.byteLength,
    seconds,
  };
}

/** Pages of the threaded module's shared memory: its declared maximum (4 GiB, web/build.sh). */
const SHARED_PAGES = { initial: 256, maximum: 65536 };

/**
 * One Web Worker per slot of `control`, each with the module instantiated on the shared
 * `memory` and waiting for a thread.
 */
async function threadPool(module, memory, control, cell, env) {
  const slots = control[0];
  const workers = [];
  const ready = [];
  for (let slot = 0; slot < slots; slot++) {
    const worker = new Worker(new URL("./thread.js", import.meta.url), { type: "module" });
    ready.push(new Promise((resolve, reject) => {
      worker.onmessage = ({ data }) => {
        if (data.kind === "ready") resolve();
      };
      worker.onerror = (e) => reject(new GmwmError(`a thread of the engine could not start: ${e.message ?? e}`));
    }));
    worker.postMessage({ module, memory, control: control.buffer, progress: cell, slot, env });
    workers.push(worker);
  }
  try {
    await Promise.all(ready);
  } catch (e) {
    workers.forEach((w) => w.terminate());
    throw e;
  }
  return { workers };
}

function collect(dir, prefix, files) {
  for (const [name, entry] of dir.contents) {
    if (entry instanceof Directory) collect(entry, `${prefix}${name}/`, files);
    else if (entry instanceof File) files.set(prefix + name, entry.data);
  }
}

/** gmwm's error line of a failed run (`gmwm: error: ...` without the prefix), else its last line. */
export function errorLine(stderr) {
  const lines = stderr.split("\n").filter((l) => l.trim() !== "");
  const error = lines.find((l) => l.startsWith("gmwm: error: ")) ??
    lines.find((l) => l.startsWith("gmwm: internal error: ")) ??
    lines.find((l) => l.startsWith("error: "));
  if (error) return error.replace(/^gmwm: error: |^gmwm: |^error: /, "");
  return lines.at(-1) ?? "gmwm failed without a message";
}

/**
 * The command line of `gmwm calibrate` for `options` (see {@link calibrate}), the recording
 * being `name`.
 */
export function calibrateArgs(name, options = {}) {
  const args = ["calibrate", name, "--json", "calibration.json"];
  const flag = (key, value) => {
    if (value !== undefined && value !== null && value !== "") args.push(key, String(value));
  };
  flag("--freq", options.freq);
  flag("--gyro-unit", options.gyroUnit);
  flag("--accel-unit", options.accelUnit);
  flag("--columns", Array.isArray(options.columns) ? options.columns.join(",") : options.columns);
  flag("--topic", options.topic);
  flag("--format", options.format);
  flag("--ncols", options.ncols);
  flag("--model", options.model);
  flag("--rule", options.rule);
  flag("--datasheet", options.datasheet);
  flag("--seed", options.seed);
  flag("--axis-policy", options.axisPolicy);
  flag("--audit", options.audit);
  if (options.robust) args.push("--robust");
  if (options.report) args.push("--report", "report.html");
  for (const stack of options.exports ?? []) {
    const file = EXPORTS[stack];
    if (!file) throw new GmwmError(`--export: unknown stack "${stack}" (${Object.keys(EXPORTS).join(", ")})`);
    if (stack === "kalibr") args.push("--kalibr", file);
    else args.push("--export", stack, file);
  }
  for (const extra of options.args ?? []) args.push(String(extra));
  return args;
}

/**
 * `gmwm calibrate` on a recording's bytes, with everything it writes.
 *
 * @param {Uint8Array|ArrayBuffer} bytes  the recording: CSV/TSV (optionally gzip), raw binary
 *   with its sidecar, a ROS1 bag or an MCAP file
 * @param {object} [options]
 * @param {string} [options.name]  the file's name, which tells its kind (`imu.csv.gz`, `run.bag`)
 * @param {Uint8Array|string|object} [options.sidecar]  its JSON sidecar (`NAME.json`)
 * @param {number} [options.freq]  sampling rate, Hz (`--freq`)
 * @param {string} [options.gyroUnit]  `rad/s`, `deg/s` or `deg/h` (`--gyro-unit`)
 * @param {string} [options.accelUnit]  `m/s^2`, `g` or `mg` (`--accel-unit`)
 * @param {string} [options.model]  full model (`--model`), e.g. `3*AR1()+WN()+RW()`
 * @param {string} [options.rule]  `navigation`, `parsimonious` or `wic-minimum`
 * @param {string} [options.topic]  the sensor_msgs/Imu topic of a bag
 * @param {boolean} [options.report]  also write the HTML report
 * @param {number} [options.audit]  self-audit replicates per axis (`--audit`; 8 with a report)
 * @param {string[]} [options.exports]  filter files: kalibr, openvins, vins, orbslam3, px4
 * @param {string[]} [options.args]  any further `gmwm calibrate` flags
 * @returns {Promise<{document: object, report?: string, exports: Object<string, string>, summary: string, notes: string[], memoryBytes: number, seconds: number}>}
 * @throws {GmwmError} gmwm's one-line error
 */
export async function calibrateAll(bytes, options = {}) {
  const name = baseName(options.name ?? "recording.csv");
  const files = { [name]: bytes };
  if (options.sidecar !== undefined && options.sidecar !== null) {
    files[`${name.replace(/(\.(csv|tsv|txt|f64|f32|f64le|f32le|bin|dat|raw))?(\.gz)?$/i, "")}.json`] = options.sidecar;
  }
  const result = await run(calibrateArgs(name, options), { ...options, files });
  if (result.code !== 0) {
    throw new GmwmError(errorLine(result.stderr), { code: result.code, stderr: result.stderr });
  }
  const text = (file) => {
    const data = result.files.get(file);
    return data ? new TextDecoder().decode(data) : undefined;
  };
  const exports = {};
  for (const stack of options.exports ?? []) {
    const written = [...result.files.keys()].filter((f) => f === EXPORTS[stack] || f.startsWith(EXPORTS[stack].replace(/\.[a-z]+$/, "") + "."));
    for (const f of written) exports[f === EXPORTS[stack] ? stack : `${stack}:${f}`] = text(f);
  }
  return {
    document: JSON.parse(text("calibration.json")),
    report: options.report ? text("report.html") : undefined,
    exports,
    summary: result.stdout,
    notes: result.stderr.split("\n").filter((l) => l !== ""),
    memoryBytes: result.memoryBytes,
    seconds: result.seconds,
  };
}

/**
 * `gmwm calibrate --json` on a recording's bytes: the JSON document (options as
 * {@link calibrateAll}).
 *
 * @returns {Promise<object>}
 * @throws {GmwmError} gmwm's one-line error
 */
export async function calibrate(bytes, options = {}) {
  return (await calibrateAll(bytes, options)).document;
}
