// The page: choose a recording (and its sidecar), set what it does not say, calibrate in a Web
// Worker (worker.js, the gmwm command in WebAssembly), show N, B, K, the report and the files.
import { readProgress } from "./pkg/shared.js";
import { EXPORTS } from "./pkg/index.js";

const $ = (id) => document.getElementById(id);
const state = { recording: null, sidecar: null, worker: null, urls: [], poll: null };

// threads need SharedArrayBuffer, which browsers give a cross-origin isolated page only
{
  const cores = Math.min(16, navigator.hardwareConcurrency || 1);
  const auto = $("threads").options[0];
  if (self.crossOriginIsolated && typeof SharedArrayBuffer !== "undefined") {
    auto.textContent = `every core (${cores})`;
  } else {
    auto.textContent = "one (this page is not served cross-origin isolated)";
    $("threads").disabled = true;
  }
}

const SIDECAR_SUFFIX = /(\.(csv|tsv|txt|f64|f32|f64le|f32le|bin|dat|raw))?(\.gz)?$/i;
const isBag = (name) => /\.(bag|mcap)$/i.test(name);

function showError(line) {
  const error = $("error");
  error.textContent = line ? `Error: ${line}` : "";
  error.hidden = !line;
}

function describe(file) {
  const mb = file.size / 1e6;
  return `${file.name} (${mb >= 1 ? mb.toFixed(1) + " MB" : file.size + " bytes"})`;
}

/** The sidecar's rate and units shown as the fields' placeholders (the command reads them). */
async function prefill() {
  const freq = $("freq");
  const units = [$("gyro-unit"), $("accel-unit")];
  freq.placeholder = "from the time column or the sidecar";
  units.forEach((u) => (u.options[0].textContent = "from the sidecar (SI for a bag)"));
  if (state.recording && isBag(state.recording.name)) {
    freq.placeholder = "from the messages' header stamps";
    units.forEach((u) => (u.options[0].textContent = "SI, as the bag's sensor_msgs/Imu"));
    return;
  }
  if (!state.sidecar) return;
  try {
    const sidecar = JSON.parse(await state.sidecar.text());
    if (Number.isFinite(sidecar.sampling_frequency_hz)) {
      freq.placeholder = `${sidecar.sampling_frequency_hz} (from the sidecar)`;
    }
    const word = (s) => (typeof s === "string" ? s.trim().split(/\s+/)[0] : null);
    const gyro = word(sidecar.units?.gyro);
    const accel = word(sidecar.units?.accel);
    if (gyro) units[0].options[0].textContent = `${gyro} (from the sidecar)`;
    if (accel) units[1].options[0].textContent = `${accel} (from the sidecar)`;
  } catch {
    // the command says what is wrong with the sidecar, in its own words
  }
}

function choose(files) {
  showError("");
  const list = [...files];
  const jsons = list.filter((f) => /\.json$/i.test(f.name));
  const data = list.filter((f) => !/\.json$/i.test(f.name));
  if (data.length > 1) {
    showError(`${data.length} recordings dropped: drop one recording (and its .json sidecar)`);
    return;
  }
  if (data.length) {
    // a new recording: the sidecar dropped with it, none otherwise (an earlier recording's
    // sidecar says nothing about this one)
    state.recording = data[0];
    state.sidecar = jsons[0] ?? null;
  } else if (jsons.length) {
    state.sidecar = jsons[0];
  }
  // the sidecar goes to the command as NAME.json beside the recording, whatever its own name
  const parts = [];
  if (state.recording) parts.push(`recording ${describe(state.recording)}`);
  if (state.sidecar) parts.push(`sidecar ${describe(state.sidecar)}`);
  $("files").textContent = parts.length ? parts.join("; ") : "No file chosen.";
  $("run").disabled = !state.recording;
  prefill();
}

function options() {
  const value = (id) => $(id).value.trim();
  return {
    freq: value("freq") || undefined,
    gyroUnit: value("gyro-unit") || undefined,
    accelUnit: value("accel-unit") || undefined,
    model: value("model") || undefined,
    rule: value("rule") || undefined,
    topic: value("topic") || undefined,
    audit: value("audit") || undefined,
    threads: $("threads").value,
    report: true,
    exports: [...document.querySelectorAll("input[name=export]:checked")].map((c) => c.value),
  };
}

function download(name, text, type) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  state.urls.push(url);
  const a = document.createElement("a");
  a.href = url;
  a.download = name;
  a.textContent = name;
  a.dataset.file = name;
  $("downloads").append(a);
}

const fmt = (x) => (x === null || x === undefined ? "-" : Number(x).toExponential(4));

function quantity(q) {
  if (!q || q.value === null || q.value === undefined) return { text: "-", value: "" };
  const ci = q.ci_low != null && q.ci_high != null ? ` [${fmt(q.ci_low)}, ${fmt(q.ci_high)}]` : "";
  const bound = q.status === "upper-bound" ? "≤ " : "";
  return { text: `${bound}${fmt(q.value)}${ci}`, value: String(q.value) };
}

function showProgress(p) {
  if (!p || p.total <= 0) return;
  $("progress").max = p.total;
  $("progress").value = p.done;
  $("status").textContent = `${p.message}: ${p.done} of ${p.total} ${p.unit}`;
}

function stopPolling() {
  clearInterval(state.poll);
  state.poll = null;
}

function show(result, started) {
  const doc = result.document;
  const body = $("nbk").querySelector("tbody");
  body.replaceChildren();
  for (const axis of doc.axes) {
    const row = document.createElement("tr");
    row.dataset.axis = axis.column;
    const cells = [axis.column, axis.canonical_model ?? axis.model ?? "-"];
    const keys = { noise_density: "n", bias_instability: "b", random_walk: "k" };
    for (const c of cells) {
      const td = document.createElement("td");
      td.textContent = c;
      row.append(td);
    }
    for (const [key, short] of Object.entries(keys)) {
      const td = document.createElement("td");
      const q = quantity(axis[key]);
      td.className = "num";
      td.textContent = q.text;
      row.dataset[short] = q.value;
      row.append(td);
    }
    const unit = document.createElement("td");
    unit.textContent = axis.noise_density?.unit ?? "";
    row.append(unit);
    body.append(row);
  }
  const wall = (performance.now() - started) / 1000;
  $("timing").textContent =
    `Calibrated in ${wall.toFixed(1)} s in this browser (the engine ${result.seconds.toFixed(1)} s, ` +
    `WebAssembly on ${result.threads === 1 ? "one thread" : `${result.threads} threads`} in Web Workers), ` +
    `WebAssembly memory ${(result.memoryBytes / 2 ** 20).toFixed(0)} MiB.`;
  $("timing").dataset.threads = result.threads;
  $("timing").dataset.engineSeconds = result.seconds;
  $("timing").dataset.memoryBytes = result.memoryBytes;
  state.urls.forEach((u) => URL.revokeObjectURL(u));
  state.urls = [];
  $("downloads").replaceChildren();
  const stem = state.recording.name.replace(SIDECAR_SUFFIX, "").replace(/\.(bag|mcap)$/i, "");
  download(`${stem}.report.html`, result.report, "text/html");
  download(`${stem}.calibration.json`, JSON.stringify(doc, null, 2) + "\n", "application/json");
  for (const [stack, text] of Object.entries(result.exports)) {
    // a per-axis file arrives as "stack:file name", one file per stack as the stack's name
    const name = stack.includes(":") ? stack.split(":")[1] : EXPORTS[stack];
    download(`${stem}.${name}`, text, "text/plain");
  }
  $("report").srcdoc = result.report;
  $("results").hidden = false;
}

async function calibrate() {
  if (!state.recording) return;
  showError("");
  $("results").hidden = true;
  $("run").disabled = true;
  $("progress-section").hidden = false;
  $("progress").removeAttribute("value");
  $("status").textContent = `reading ${state.recording.name} ...`;
  const started = performance.now();
  const bytes = new Uint8Array(await state.recording.arrayBuffer());
  const sidecar = state.sidecar ? new Uint8Array(await state.sidecar.arrayBuffer()) : undefined;
  state.worker?.terminate();
  stopPolling();
  let worker;
  try {
    worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module" });
  } catch (e) {
    $("progress-section").hidden = true;
    $("run").disabled = false;
    showError(`this browser cannot start the calibration worker here (${e.message}); serve the folder over http (python3 -m http.server)`);
    return;
  }
  state.worker = worker;
  worker.onmessage = ({ data }) => {
    if (data.kind === "started") {
      // the engine's other threads report here, while the worker itself is busy
      if (data.cell) {
        state.poll = setInterval(() => {
          const p = readProgress(data.cell);
          if (p?.trap) {
            // the worker waits for a thread that will not come back
            stopPolling();
            worker.terminate();
            $("run").disabled = false;
            $("progress-section").hidden = true;
            showError(p.trap);
            return;
          }
          showProgress(p);
        }, 250);
      }
      return;
    }
    if (data.kind === "progress") {
      showProgress(data.progress);
      return;
    }
    stopPolling();
    worker.terminate();
    state.worker = null;
    $("run").disabled = false;
    $("progress-section").hidden = true;
    if (data.kind === "error") {
      showError(data.line);
      return;
    }
    show(data.result, started);
  };
  worker.onerror = (e) => {
    stopPolling();
    $("run").disabled = false;
    $("progress-section").hidden = true;
    showError(`the calibration worker failed: ${e.message ?? "it could not be loaded"}`);
  };
  // the bytes are moved, not copied, into the worker
  const transfer = [bytes.buffer, ...(sidecar ? [sidecar.buffer] : [])];
  worker.postMessage({ bytes, name: state.recording.name, sidecar, options: options() }, transfer);
}

const drop = $("drop");
drop.addEventListener("click", () => $("pick").click());
drop.addEventListener("keydown", (e) => (e.key === "Enter" || e.key === " ") && $("pick").click());
$("pick").addEventListener("change", (e) => choose(e.target.files));
drop.addEventListener("dragover", (e) => {
  e.preventDefault();
  drop.classList.add("over");
});
drop.addEventListener("dragleave", () => drop.classList.remove("over"));
drop.addEventListener("drop", (e) => {
  e.preventDefault();
  drop.classList.remove("over");
  choose(e.dataTransfer.files);
});
$("run").addEventListener("click", calibrate);
