#!/usr/bin/env python3
"""The real-sensor table of issue 28: one row per axis of every `gmwm calibrate --json` document
in a folder (model, verdict, worst deviation and its cause, N, B, K with intervals), then the
counts the issue asks for (explained, B given, K above the Allan-band bound, contamination that
matters, B from a flicker term).

    mkdir out && for f in ../shared/data/*.csv.gz; do
        gmwm calibrate "$f" --json out/$(basename "$f" .csv.gz).json -q; done
    python3 crates/gmwm/tools/real_sensor_table.py out
"""
import glob
import json
import math
import os
import sys


def fmt(e):
    if not e:
        return "-"
    s = f"{e['value']:.3g}"
    if e.get("ci_low") is not None and e.get("ci_high") is not None:
        s += f" [{e['ci_low']:.3g}, {e['ci_high']:.3g}]"
    elif e.get("status") == "upper-bound":
        s = "<= " + s
    return s


def main(folder):
    total = explained = b_given = k_above = matters = b_flicker = 0
    print("| recording | axis | model | verdict | worst dev (tau s) | cause | N | B | K (status) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
        for a in json.load(open(path))["axes"]:
            total += 1
            v = a["verdict"]
            explained += v["explains_wv"]
            w = v.get("worst")
            worst = f"{100 * w['deviation']:+.0f}% ({w['tau_s']:.3g})" if w else "-"
            b, k = a.get("bias_instability"), a.get("random_walk")
            b_given += b is not None
            b_flicker += bool(b and "FN" in b.get("source", ""))
            av = a["allan"]
            bound = min(math.sqrt(3 * h / t) for h, t in zip(av["ci_high"], av["tau_s"]))
            k_above += bool(k and k["value"] > bound * (1 + 1e-9))
            c = a.get("contamination")
            matters += bool(c and c.get("matters"))
            name = os.path.basename(path)[:-5]
            verdict = "explained" if v["explains_wv"] else "misfit"
            status = k["status"] if k else "-"
            print(
                f"| {name} | {a['column']} | {a['canonical_model']} | {verdict} | {worst} | "
                f"{w['cause'] if w else ''} | {fmt(a.get('noise_density'))} | {fmt(b)} | {fmt(k)} ({status}) |"
            )
    print(
        f"\nexplained {explained}/{total}; B given {b_given}/{total} ({b_flicker} from an FN term); "
        f"K above the Allan-band bound {k_above}; contamination matters {matters}"
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
