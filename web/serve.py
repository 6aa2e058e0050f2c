#!/usr/bin/env python3
"""Serves the built page (web/dist) on localhost with the headers that make it cross-origin
isolated, so that the browser gives it SharedArrayBuffer and the page runs the engine on every
core (any static server works too, on one thread):

    web/build.sh && python3 web/serve.py            # then http://127.0.0.1:8000/
    python3 web/serve.py --port 9000 --dir web/dist
"""

from __future__ import annotations

import argparse
import functools
import http.server
from pathlib import Path

ISOLATION = {
    "Cross-Origin-Opener-Policy": "same-origin",
    "Cross-Origin-Embedder-Policy": "require-corp",
}


def handler(directory: Path, extra: dict[str, Path] | None = None, quiet: bool = True):
    """A request handler serving `directory` with the isolation headers and the right type for
    .wasm; `extra` maps `/__test/NAME` to files outside it (the browser test's inputs)."""
    extra = extra or {}

    class Handler(http.server.SimpleHTTPRequestHandler):
        extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map,
                          ".wasm": "application/wasm", ".js": "text/javascript"}

        def end_headers(self) -> None:
            for key, value in ISOLATION.items():
                self.send_header(key, value)
            super().end_headers()

        def translate_path(self, path: str) -> str:
            if path.startswith("/__test/"):
                name = path.split("/", 2)[2].split("?", 1)[0]
                if name in extra:
                    return str(extra[name])
            return super().translate_path(path)

        def log_message(self, *args) -> None:
            if not quiet:
                super().log_message(*args)

    return functools.partial(Handler, directory=str(directory))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--port", type=int, default=8000)
    parser.add_argument("--dir", default=str(Path(__file__).resolve().parent / "dist"))
    args = parser.parse_args()
    directory = Path(args.dir)
    if not (directory / "index.html").is_file():
        raise SystemExit(f"serve.py: {directory} has no index.html: run web/build.sh first")
    server = http.server.ThreadingHTTPServer(("127.0.0.1", args.port),
                                             handler(directory, quiet=False))
    print(f"serving {directory} at http://127.0.0.1:{args.port}/ (cross-origin isolated)")
    server.serve_forever()


if __name__ == "__main__":
    main()
