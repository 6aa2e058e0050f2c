#!/usr/bin/env python3
"""Check a self-contained HTML report in headless Chromium.

Usage: check_report.py REPORT.html SCREENSHOT.png [--min-figures N] [--timeout S]

The report is opened from its file:// URL with network access blocked.  The
check fails (exit 1, one ``check_report: `` line per problem on stderr) on
console errors, uncaught page errors, requests for anything but the report itself
and inline data: URIs (a sibling file too: the report must be self-contained),
broken images, too few figures, a missing <h1>, figure images that vanish in
print, or when the total deadline passes.  A full-page screenshot is saved
whenever the page loaded.  Exit 2 means a usage error, exit 3 a missing
dependency (the pip package ``playwright`` or Debian's ``chromium``).
"""

from __future__ import annotations

import argparse
import os
import struct
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlsplit

PREFIX = "check_report: "
USAGE = "check_report.py REPORT.html SCREENSHOT.png [--min-figures N] [--timeout S]"
EXIT_OK, EXIT_FAIL, EXIT_USAGE, EXIT_MISSING = 0, 1, 2, 3

DEFAULT_CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    # Defence in depth for what request routing cannot see (DNS prefetch,
    # WebSockets, WebRTC): no name resolves, and any connection is sent to
    # a closed port on the loopback interface instead of leaving the machine.
    "--host-resolver-rules=MAP * ~NOTFOUND",
    "--proxy-server=127.0.0.1:9",
    "--force-webrtc-ip-handling-policy=disable_non_proxied_udp",
]
# a self-contained report loads nothing but itself, data: URIs and about: pages
INLINE_SCHEMES = frozenset({"data", "about"})
VIEWPORT = {"width": 1280, "height": 900}
WATCHDOG_GRACE_S = 5.0
MAX_URL_CHARS = 100

JS_IMAGES = """() => Array.from(document.images, img => ({
    src: img.currentSrc || img.src,
    complete: img.complete,
    naturalWidth: img.naturalWidth,
    inFigure: img.closest('figure') !== null,
}))"""
JS_HAS_H1 = "() => document.querySelector('h1') !== null"
JS_FIGURE_BOXES = """() => Array.from(document.querySelectorAll('figure img'))
    .filter(img => img.naturalWidth > 0)
    .map(img => ({
        src: img.currentSrc || img.src,
        width: img.getBoundingClientRect().width,
    }))"""


class Fatal(Exception):
    """A condition that ends the run at once with the given exit code."""

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


class ArgumentParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line and exit code 2."""

    def error(self, message: str) -> None:
        raise Fatal(EXIT_USAGE, f"{message} (usage: {USAGE})")


@dataclass
class Outcome:
    """What one run found: problems in order, counts and the screenshot."""

    problems: list[str] = field(default_factory=list)
    external: set[str] = field(default_factory=set)
    figures: int = 0
    images: int = 0
    screenshot_size: tuple[int, int] | None = None

    def add(self, problem: str) -> None:
        """Record one problem."""
        self.problems.append(problem)

    def add_external(self, url: str) -> None:
        """Record a request that would leave the machine, once per URL."""
        if url not in self.external:
            self.external.add(url)
            self.add(f"external request: {url}")


class Deadline:
    """The total time budget, handed out as Playwright timeouts."""

    def __init__(self, seconds: float):
        self.seconds = seconds
        self.end = time.monotonic() + seconds

    def ms(self) -> int:
        """Milliseconds left, at least 1 (Playwright reads 0 as 'no limit')."""
        return max(1, int((self.end - time.monotonic()) * 1000))


def parse_args(argv: list[str]) -> argparse.Namespace:
    """Parse and validate the command line; raise Fatal(2) on bad input."""
    parser = ArgumentParser(usage=USAGE, description=__doc__.splitlines()[0])
    parser.add_argument("report", type=Path, help="the HTML report to check")
    parser.add_argument("screenshot", type=Path, help="where to save the full-page PNG")
    parser.add_argument(
        "--min-figures", type=int, default=1, metavar="N",
        help="fail below N loaded <figure> images (default 1)",
    )
    parser.add_argument(
        "--timeout", type=float, default=60.0, metavar="S",
        help="total deadline in seconds (default 60)",
    )
    args = parser.parse_args(argv)
    if args.min_figures < 0:
        parser.error("--min-figures must be >= 0")
    if not args.timeout > 0:
        parser.error("--timeout must be > 0")
    if not args.report.is_file():
        raise Fatal(EXIT_USAGE, f"report not found: {args.report}")
    if not args.screenshot.resolve().parent.is_dir():
        raise Fatal(EXIT_USAGE, f"screenshot directory not found: {args.screenshot.parent}")
    return args


def start_watchdog(deadline_s: float) -> None:
    """Exit at once if still running WATCHDOG_GRACE_S after the deadline.

    This catches hangs that Playwright timeouts miss (page.evaluate has no
    timeout, a wedged browser may never answer); the Playwright driver then
    sees its pipe close and kills the browser.
    """

    def expire() -> None:
        sys.stderr.write(
            f"{PREFIX}watchdog: still running {WATCHDOG_GRACE_S:g} s after the "
            f"{deadline_s:g} s deadline, aborting\n"
        )
        sys.stderr.flush()
        os._exit(EXIT_FAIL)

    timer = threading.Timer(deadline_s + WATCHDOG_GRACE_S, expire)
    timer.daemon = True
    timer.start()


def import_playwright():
    """Return playwright.sync_api, or raise Fatal(3) saying how to install it."""
    try:
        from playwright import sync_api
    except ImportError as err:
        raise Fatal(
            EXIT_MISSING,
            f"Python package playwright missing ({err}): run `python3 -m pip install playwright`",
        ) from err
    return sync_api


def find_chromium() -> str:
    """Return the Chromium executable, or raise Fatal(3) if it is missing."""
    path = os.environ.get("GMWM_CHROMIUM") or DEFAULT_CHROMIUM
    if not os.access(path, os.X_OK):
        raise Fatal(
            EXIT_MISSING,
            f"chromium not found at {path}: install the Debian package `chromium` "
            "or set GMWM_CHROMIUM",
        )
    return path


def shorten(url: str) -> str:
    """Cut long URLs (inline data: images) down for one-line messages."""
    return url if len(url) <= MAX_URL_CHARS else url[: MAX_URL_CHARS - 3] + "..."


def is_self_contained(url: str, report_url: str) -> bool:
    """Tell whether a request is the report itself or inline (data:, about:): anything else,
    a sibling file included, means the report is not self-contained."""
    if urlsplit(url).scheme.lower() in INLINE_SCHEMES:
        return True
    return url.split("#", 1)[0] == report_url


def png_size(path: Path) -> tuple[int, int]:
    """Read width and height from a PNG file's IHDR chunk."""
    with path.open("rb") as png:
        head = png.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"not a PNG file: {path}")
    return struct.unpack(">II", head[16:24])


def block_network(context, outcome: Outcome, report_url: str) -> None:
    """Abort every request but the report's own and inline ones, reporting each as external."""

    def route(route) -> None:
        if is_self_contained(route.request.url, report_url):
            route.continue_()
        else:
            route.abort()

    def on_request(request) -> None:
        if not is_self_contained(request.url, report_url):
            outcome.add_external(shorten(request.url))

    context.route("**/*", route)
    context.on("request", on_request)


def watch_page(page, outcome: Outcome) -> None:
    """Report console errors, uncaught exceptions and WebSockets as problems."""

    def on_console(message) -> None:
        if message.type == "error":
            where = message.location.get("url")
            suffix = f" ({shorten(where)})" if where else ""
            outcome.add(f"console error: {message.text}{suffix}")

    def on_page_error(error) -> None:
        outcome.add(f"page error: {error.name}: {error.message}")

    def on_websocket(websocket) -> None:
        outcome.add_external(shorten(websocket.url))

    page.on("console", on_console)
    page.on("pageerror", on_page_error)
    page.on("websocket", on_websocket)


def check_content(page, outcome: Outcome, min_figures: int) -> None:
    """Check the heading, broken images and the number of figures."""
    if not page.evaluate(JS_HAS_H1):
        outcome.add("no <h1> heading")
    images = page.evaluate(JS_IMAGES)
    for img in images:
        if not img["complete"] or img["naturalWidth"] == 0:
            outcome.add(f"broken image: {shorten(img['src'])}")
    outcome.images = len(images)
    outcome.figures = sum(1 for img in images if img["inFigure"] and img["naturalWidth"] > 0)
    if outcome.figures < min_figures:
        outcome.add(f"too few figures: {outcome.figures}, expected at least {min_figures}")


def check_print(page, outcome: Outcome) -> None:
    """Check that no figure image collapses to zero width in print media."""
    page.emulate_media(media="print")
    for img in page.evaluate(JS_FIGURE_BOXES):
        if img["width"] == 0:
            outcome.add(f"figure image has zero width in print: {shorten(img['src'])}")
    page.emulate_media(media="screen")


def inspect_report(browser, args: argparse.Namespace, deadline: Deadline, outcome: Outcome) -> None:
    """Load the report, run all page checks and save the screenshot."""
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1, service_workers="block")
    context.set_default_timeout(deadline.ms())
    block_network(context, outcome, args.report.resolve().as_uri())
    page = context.new_page()
    watch_page(page, outcome)
    page.goto(args.report.resolve().as_uri(), wait_until="load", timeout=deadline.ms())
    check_content(page, outcome, args.min_figures)
    check_print(page, outcome)
    page.screenshot(path=str(args.screenshot), full_page=True, timeout=deadline.ms())
    outcome.screenshot_size = png_size(args.screenshot)


def first_line(err: Exception) -> str:
    """The first non-empty line of an exception's message."""
    lines = [line.strip() for line in str(err).splitlines() if line.strip()]
    return lines[0] if lines else type(err).__name__


def launch(pw, sync_api, chromium: str, deadline: Deadline):
    """Start headless Chromium; raise Fatal(3) if it cannot start at all."""
    try:
        return pw.chromium.launch(
            executable_path=chromium, headless=True, args=CHROMIUM_ARGS, timeout=deadline.ms()
        )
    except sync_api.TimeoutError:
        raise
    except sync_api.Error as err:
        raise Fatal(EXIT_MISSING, f"could not launch {chromium}: {first_line(err)}") from err


def check_report(sync_api, chromium: str, args: argparse.Namespace) -> Outcome:
    """Run the whole check within the deadline and return what it found."""
    deadline = Deadline(args.timeout)
    outcome = Outcome()
    try:
        with sync_api.sync_playwright() as pw:
            browser = launch(pw, sync_api, chromium, deadline)
            try:
                inspect_report(browser, args, deadline, outcome)
            finally:
                browser.close()
    except sync_api.TimeoutError as err:
        outcome.add(f"deadline of {deadline.seconds:g} s exceeded: {first_line(err)}")
    except sync_api.Error as err:
        outcome.add(f"browser error: {first_line(err)}")
    return outcome


def main(argv: list[str]) -> int:
    """Run the checker and return its exit code."""
    try:
        args = parse_args(argv)
        start_watchdog(args.timeout)
        outcome = check_report(import_playwright(), find_chromium(), args)
    except Fatal as fatal:
        print(f"{PREFIX}{fatal}", file=sys.stderr)
        return fatal.code
    for problem in outcome.problems:
        print(f"{PREFIX}{problem}", file=sys.stderr)
    if outcome.problems:
        return EXIT_FAIL
    width, height = outcome.screenshot_size
    print(
        f"{PREFIX}OK: {outcome.figures} figures, {outcome.images} images, "
        f"screenshot {args.screenshot} ({width}x{height})"
    )
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
