#!/usr/bin/env python3
"""End-to-end test of the browser page (web/dist, built by web/build.sh) in Debian's Chromium,
driven by playwright (its own browser download is not used).

The page is served by a local static server; the test drops a recording and its sidecar on the
drop zone (a real `drop` event carrying File objects), waits for the calibration, and checks:

- N, B, K of every axis, as the page shows them, equal `gmwm calibrate --json` of the native
  command on the same file to REL_TOL relative (the same Rust code; WebAssembly's libm and the
  host's differ in the last bits of some elementary functions, see REL_TOL);
- the downloaded Kalibr file equals the native command's `--kalibr` file;
- a corrupt recording shows exactly one error line, the native command's;
- the page stayed responsive during the calibration (a timer on the main thread kept firing);
- with threads (the server sends the cross-origin isolation headers, so the page runs the
  threaded module on every core) and on one thread, the page shows the same N, B, K.

It prints the in-browser time and memory beside the native command's, and saves screenshots
(before, during, after, error) to --shots.

    python3 web/tests/check_web.py --gmwm target/release/gmwm \\
        --recording ../shared/data/adis_16405_imu1.csv.gz --shots target/web-shots

Exit status: 0 passed, 1 failed, 3 a dependency missing (playwright, chromium, web/dist).
"""

from __future__ import annotations

import argparse
import http.server
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from serve import handler  # noqa: E402  (web/serve.py)

PREFIX = "check_web: "
EXIT_FAIL, EXIT_MISSING = 1, 3
# N, B, K of the page against the native command's: the bar. The engine takes the
# elementary functions whose glibc and musl algorithms differ from one implementation
# (crates/gmwm/src/math/elementary.rs); what remains (exp, ln, powf, statrs, rustfft) moves this
# recording's N, B, K by 1.5e-10 (by 1.4e-9 before that module).
REL_TOL = 1e-9
# self-audit recordings per axis in the page and the command (the page's default is the
# command's, 8 with a report, which is most of the time: CI's test runs none; --audit 8 times
# what a user gets by default)
AUDIT = 0
ROOT = Path(__file__).resolve().parents[2]
# headless as root, no background network on a closed machine; unlike the report's test
# (check_report.py), which maps every host name nowhere, this page loads from a local server
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


class Fatal(Exception):
    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


def serve(dist: Path, data: dict[str, Path]) -> tuple[http.server.ThreadingHTTPServer, str]:
    """The page's server (web/serve.py: cross-origin isolated, so with threads) of `dist` on a
    free loopback port; `/__test/NAME` serves the test's input files (the page fetches them
    into File objects for the drop)."""
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler(dist, data))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}/"


DROP = """async (names) => {
  const dt = new DataTransfer();
  for (const name of names) {
    const blob = await (await fetch('/__test/' + name)).blob();
    dt.items.add(new File([blob], name));
  }
  const zone = document.getElementById('drop');
  zone.dispatchEvent(new DragEvent('dragover', {dataTransfer: dt, bubbles: true, cancelable: true}));
  zone.dispatchEvent(new DragEvent('drop', {dataTransfer: dt, bubbles: true, cancelable: true}));
}"""

# a main-thread timer: if the calibration blocked the page, it would stop counting
HEARTBEAT = """() => { window.__beats = 0; window.__beat = setInterval(() => window.__beats++, 100); }"""


def native(gmwm: Path, recording: Path, out: Path, audit: int, threads: int | None = None):
    """The native command's document and Kalibr file, and its wall time, with what the page
    asks (the report, with `audit` self-audit recordings per axis); on `threads` threads."""
    env = dict(os.environ, **({"RAYON_NUM_THREADS": str(threads)} if threads else {}))
    started = time.perf_counter()
    subprocess.run([str(gmwm), "calibrate", str(recording), "--json", str(out / "native.json"),
                    "--kalibr", str(out / "native_kalibr.yaml"), "--report",
                    str(out / "native.html"), "--audit", str(audit), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL, env=env)
    seconds = time.perf_counter() - started
    return (json.loads((out / "native.json").read_text()),
            (out / "native_kalibr.yaml").read_text(), seconds)


def native_error(gmwm: Path, corrupt: Path) -> str:
    run = subprocess.run([str(gmwm), "calibrate", str(corrupt), "--quiet"],
                         capture_output=True, text=True)
    lines = [l for l in run.stderr.splitlines() if l.strip()]
    if run.returncode == 0 or not lines:
        raise Fatal(EXIT_FAIL, f"the native command accepted the corrupt file {corrupt}")
    # the page's file has no folder: the command's line with the file named as the page names it
    return lines[-1].removeprefix("gmwm: error: ").replace(str(corrupt), corrupt.name)


def rel(a: float, b: float) -> float:
    return 0.0 if a == b else abs(a - b) / max(abs(a), abs(b))


def check(args: argparse.Namespace) -> list[str]:
    try:
        from playwright import sync_api
    except ImportError as err:
        raise Fatal(EXIT_MISSING, f"Python package playwright missing ({err}): "
                    "python3 -m pip install playwright") from err
    chromium = os.environ.get("GMWM_CHROMIUM", "/usr/bin/chromium")
    if not os.access(chromium, os.X_OK):
        raise Fatal(EXIT_MISSING, f"chromium not found at {chromium}: install Debian's chromium")
    dist = ROOT / "web" / "dist"
    if not (dist / "pkg" / "gmwm.wasm").is_file():
        raise Fatal(EXIT_MISSING, f"{dist} is not built: run web/build.sh")
    recording = Path(args.recording).resolve()
    sidecar = recording.with_name(recording.name.removesuffix(".gz").rsplit(".", 1)[0] + ".json")
    shots = Path(args.shots)
    shots.mkdir(parents=True, exist_ok=True)
    problems: list[str] = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        doc, kalibr, native_s = native(Path(args.gmwm), recording, tmp, args.audit)
        native_one_s = (native(Path(args.gmwm), recording, tmp, args.audit, threads=1)[2]
                        if args.native_one_thread else None)
        corrupt = tmp / "corrupt.csv.gz"
        # a gzip header, then bytes that are no deflate stream
        corrupt.write_bytes(b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03" + bytes(range(256)) * 8)
        expected_error = native_error(Path(args.gmwm), corrupt)
        data = {recording.name: recording, corrupt.name: corrupt}
        if sidecar.is_file():
            data[sidecar.name] = sidecar
        server, url = serve(dist, data)
        try:
            with sync_api.sync_playwright() as pw:
                browser = pw.chromium.launch(executable_path=chromium, headless=True,
                                             args=CHROMIUM_ARGS)
                try:
                    page = browser.new_page(viewport={"width": 1200, "height": 900},
                                            accept_downloads=True)
                    console: list[str] = []
                    page.on("console", lambda m: console.append(f"{m.type}: {m.text}"))
                    page.on("pageerror", lambda e: console.append(f"page error: {e}"))
                    page.goto(url)
                    page.screenshot(path=str(shots / "1-before.png"), full_page=True)
                    page.evaluate(DROP, [n for n in data if n != corrupt.name])
                    page.wait_for_function("!document.getElementById('run').disabled")
                    page.fill("#audit", str(args.audit))
                    if not page.evaluate("self.crossOriginIsolated"):
                        problems.append("the page is not cross-origin isolated: no threads")
                    page.evaluate(HEARTBEAT)
                    started = time.perf_counter()
                    page.click("#run")
                    page.wait_for_function(
                        "document.getElementById('progress').value > 0", timeout=60_000)
                    page.screenshot(path=str(shots / "2-during.png"), full_page=True)
                    page.wait_for_selector("#results:not([hidden]), #error:not([hidden])",
                                           timeout=args.timeout * 1000)
                    browser_s = time.perf_counter() - started
                    beats = page.evaluate("window.__beats")
                    if not page.is_hidden("#error"):
                        problems.append(f"the page showed an error: {page.inner_text('#error')}")
                        return problems + console
                    page.screenshot(path=str(shots / "3-after.png"), full_page=True)
                    timing = page.eval_on_selector("#timing", "e => ({...e.dataset})")
                    # the page's timer fires every 100 ms; a blocked main thread would stop it
                    if beats < 0.5 * browser_s * 10:
                        problems.append(f"the page was unresponsive: {beats} timer ticks in "
                                        f"{browser_s:.1f} s")
                    rows = page.eval_on_selector_all(
                        "#nbk tbody tr", "rs => rs.map(r => ({...r.dataset}))")
                    problems += compare_nbk(rows, doc)
                    link = page.locator("#downloads a[data-file$='kalibr_imu.yaml']")
                    with page.expect_download() as info:
                        link.click()
                    got = Path(info.value.path()).read_text()
                    if got != kalibr:
                        problems.append("the downloaded Kalibr file differs from the command's")
                    frame_text = page.frame_locator("#report").locator("body").inner_text()
                    if "noise density" not in frame_text.lower():
                        problems.append("the report in the page has no noise density")
                    cores = page.evaluate("navigator.hardwareConcurrency")
                    if cores > 1 and int(timing["threads"]) < 2:
                        problems.append(f"{cores} cores but the page ran {timing['threads']} thread")
                    # the same on one thread: the same numbers (the engine's results do not
                    # depend on the thread count)
                    page.select_option("#threads", "1")
                    started = time.perf_counter()
                    page.click("#run")
                    page.wait_for_selector("#results:not([hidden]), #error:not([hidden])",
                                           state="visible", timeout=args.timeout * 1000)
                    page.wait_for_function("document.getElementById('timing').dataset.threads === '1'",
                                           timeout=args.timeout * 1000)
                    one_s = time.perf_counter() - started
                    one = page.eval_on_selector("#timing", "e => ({...e.dataset})")
                    rows_one = page.eval_on_selector_all(
                        "#nbk tbody tr", "rs => rs.map(r => ({...r.dataset}))")
                    if rows_one != rows:
                        problems.append("N, B, K on one thread differ from those with threads")
                    native_line = (f"native command: {native_s:.2f} s on all cores, "
                                   f"{native_one_s:.2f} s on one" if native_one_s else
                                   f"native command: {native_s:.2f} s")
                    print(f"{PREFIX}in the browser: {browser_s:.2f} s wall on {timing['threads']} "
                          f"threads (engine {float(timing['engineSeconds']):.2f} s, WebAssembly "
                          f"memory {int(timing['memoryBytes']) / 2**20:.0f} MiB), {one_s:.2f} s "
                          f"on one (engine {float(one['engineSeconds']):.2f} s, "
                          f"{int(one['memoryBytes']) / 2**20:.0f} MiB); {native_line}; "
                          f"gmwm.wasm {(dist / 'pkg' / 'gmwm.wasm').stat().st_size / 2**20:.1f} MiB, "
                          f"gmwm-threads.wasm "
                          f"{(dist / 'pkg' / 'gmwm-threads.wasm').stat().st_size / 2**20:.1f} MiB")
                    # the corrupt file: one line, the command's
                    page.evaluate(DROP, [corrupt.name])
                    page.click("#run")
                    page.wait_for_selector("#error:not([hidden])", timeout=60_000)
                    shown = page.inner_text("#error").strip()
                    page.screenshot(path=str(shots / "4-error.png"), full_page=True)
                    if len(shown.splitlines()) != 1:
                        problems.append(f"the error is not one line: {shown!r}")
                    if shown != f"Error: {expected_error}":
                        problems.append(f"the page's error {shown!r} is not the command's "
                                        f"{expected_error!r}")
                    print(f"{PREFIX}corrupt file: {shown}")
                finally:
                    browser.close()
        finally:
            server.shutdown()
    if problems and console:
        problems.append("browser console: " + " | ".join(console[-5:]))
    return problems


def compare_nbk(rows: list[dict], doc: dict) -> list[str]:
    problems = []
    axes = {a["column"]: a for a in doc["axes"]}
    if sorted(r.get("axis") for r in rows) != sorted(axes):
        return [f"the page shows axes {[r.get('axis') for r in rows]}, the command {list(axes)}"]
    worst = 0.0
    for row in rows:
        axis = axes[row["axis"]]
        for short, key in (("n", "noise_density"), ("b", "bias_instability"), ("k", "random_walk")):
            want = axis[key]["value"]
            got = row.get(short, "")
            if want is None:
                if got != "":
                    problems.append(f"{row['axis']} {key}: page {got}, command none")
                continue
            r = rel(float(got), want)
            worst = max(worst, r)
            if r > REL_TOL:
                problems.append(f"{row['axis']} {key}: page {got}, command {want!r} "
                                f"(relative {r:.2e} > {REL_TOL:g})")
    print(f"{PREFIX}N, B, K of {len(rows)} axes: largest relative difference to the command "
          f"{worst:.2e}")
    return problems


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--gmwm", default=str(ROOT / "target" / "release" / "gmwm"))
    parser.add_argument("--recording", default=str(ROOT.parent / "shared" / "data" /
                                                   "adis_16405_imu1.csv.gz"))
    parser.add_argument("--shots", default=str(ROOT / "target" / "web-shots"))
    parser.add_argument("--timeout", type=float, default=300)
    parser.add_argument("--audit", type=int, default=AUDIT,
                        help="self-audit recordings per axis, in the page and the command")
    parser.add_argument("--native-one-thread", action="store_true",
                        help="also time the native command on one thread")
    args = parser.parse_args(argv)
    try:
        problems = check(args)
    except Fatal as fatal:
        print(f"{PREFIX}{fatal}", file=sys.stderr)
        return fatal.code
    for p in problems:
        print(f"{PREFIX}{p}", file=sys.stderr)
    if problems:
        return EXIT_FAIL
    print(f"{PREFIX}passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
