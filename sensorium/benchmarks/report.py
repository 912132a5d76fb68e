"""Write ``benchmarks.json``, ``benchmarks.md`` and the PNG plots (``bench/*.png``, matplotlib
optional) from the sections' results. With ``--only`` the other sections of an existing
``benchmarks.json`` in the output folder are kept (each section records when it was measured)."""

from __future__ import annotations

import json
import math
from pathlib import Path

SCHEMA = 1
ORDER = ("peers", "accuracy", "scaling", "memory", "limits", "transport", "scaleout", "loading", "cad", "images", "training", "radio")


def load(out: Path) -> dict:
    path = out / "benchmarks.json"
    if path.is_file():
        try:
            doc = json.loads(path.read_text())
            if doc.get("schema") == SCHEMA:
                return doc
        except (OSError, ValueError):
            pass
    return {}


def write(out: Path, doc: dict, plots: bool = True, log=print) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    written = []
    pngs: dict[str, str] = {}
    if plots:
        pngs, note = render_plots(out, doc)
        if note:
            doc["plots_note"] = note
            log(f"  report: {note}")
    doc["plots"] = {**doc.get("plots", {}), **pngs}
    # drop references to PNGs that no longer exist
    doc["plots"] = {k: v for k, v in doc["plots"].items() if (out / v).is_file()}
    path = out / "benchmarks.json"
    path.write_text(json.dumps(doc, indent=1, sort_keys=False, allow_nan=False) + "\n")
    written.append(path)
    md = out / "benchmarks.md"
    md.write_text(markdown(doc))
    written.append(md)
    return written


# ---------------------------------------------------------------------------------- plots
def render_plots(out: Path, doc: dict) -> tuple[dict[str, str], str]:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except Exception as exc:  # noqa: BLE001 - optional extra
        return {}, f"no plots: matplotlib is not installed ({type(exc).__name__}); pip install 'sensorium[bench]'"
    folder = out / "bench"
    folder.mkdir(parents=True, exist_ok=True)
    made: dict[str, str] = {}
    for name, sec in doc.get("sections", {}).items():
        if not sec.get("_fresh"):
            continue
        for p in sec.get("plots", []):
            key = f"{name}_{p['id']}"
            fig, ax = plt.subplots(figsize=(7.0, 4.2), dpi=110)
            try:
                _draw(ax, p)
                ax.set_title(p["title"], fontsize=11)
                fig.subplots_adjust(left=0.36 if p.get("kind") == "bar" else 0.12, right=0.97, top=0.91, bottom=0.13)
                rel = f"bench/{key}.png"
                fig.savefig(out / rel)
                made[key] = rel
            finally:
                plt.close(fig)
            if name == "peers" and p["id"] == "throughput":
                fig, ax = plt.subplots(figsize=(7.5, 3.8), dpi=120)
                try:
                    _draw(ax, p, headline=True)
                    ax.set_title(p["title"].replace("(log scale)", "— higher is better"), fontsize=11)
                    fig.subplots_adjust(left=0.36, right=0.97, top=0.9, bottom=0.14)
                    fig.savefig(out / "bench" / "headline.png")
                    made["headline"] = "bench/headline.png"
                finally:
                    plt.close(fig)
    return made, ""


def _draw(ax, p: dict, headline: bool = False) -> None:
    series = p["series"]
    if p.get("kind") == "bar":
        labels = [s["label"] for s in series]
        vals = [s["y"][0] if s["y"] and s["y"][0] is not None else 0.0 for s in series]
        colors = ["#d62728" if lab.startswith("Sensorium") else ("#7f7f7f" if lab == "raw embreex" else "#1f77b4")
                  for lab in labels]
        y = list(range(len(labels)))[::-1]
        ax.barh(y, vals, color=colors)
        ax.set_yticks(y)
        ax.set_yticklabels(labels, fontsize=8)
        ax.set_xscale("log")
        ax.set_xlabel(p["ylabel"])
        for yi, v in zip(y, vals):
            if v > 0:
                ax.text(v, yi, f" {v:.2g}", va="center", fontsize=7)
        ax.grid(axis="x", alpha=0.3)
        return
    for s in series:
        xs = [x for x, y in zip(s["x"], s["y"]) if x is not None and y is not None]
        ys = [y for x, y in zip(s["x"], s["y"]) if x is not None and y is not None]
        if not xs:
            continue
        style = "o-" if p.get("kind") != "pareto" or len(xs) > 1 else "o"
        line, = ax.plot(xs, ys, style, label=s["label"], markersize=4)
        for x, y, lab in zip(xs, ys, s.get("labels") or []):
            ax.annotate(lab, (x, y), textcoords="offset points", xytext=(3, 3), fontsize=6, color=line.get_color())
    if p.get("logx") and all(x > 0 for s in series for x in s["x"] if x is not None):
        ax.set_xscale("log")
    if p.get("logy") and all(y > 0 for s in series for y in s["y"] if y is not None):
        ax.set_yscale("log")
    ax.set_xlabel(p["xlabel"])
    ax.set_ylabel(p["ylabel"])
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)


# ---------------------------------------------------------------------------------- markdown
def _cell(v) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        if not math.isfinite(v):
            return "–"
        return f"{v:.4g}"
    return str(v).replace("|", "\\|").replace("\n", " ")


def _verdict(ok) -> str:
    return "**PASS**" if ok is True else ("**MISS**" if ok is False else "not measured")


def markdown(doc: dict) -> str:
    L: list[str] = []
    m = doc.get("machine", {})
    L.append("# Sensorium benchmarks\n")
    L.append("Reproduce (from a checkout; the `bench-peers` extra brings matplotlib and the optional peers):\n")
    L.append("```sh")
    L.append("python -m pip install -e '.[bench-peers]'   # Open3D on Debian also needs: apt-get install libusb-1.0-0")
    L.append(doc.get("command", "sensorium bench --out docs/"))
    L.append("```\n")
    L.append(f"`sensorium bench --quick` is a smoke run (about 5 min on 2 cores); `--only SECTION` (repeatable: "
             f"{', '.join(ORDER)}) re-measures some sections and keeps the others of an existing report.\n")
    L.append(f"Measured {doc.get('generated', '?')} on {m.get('cpu', '?')}, {m.get('cpus', '?')} cores, Python "
             f"{m.get('python', '?')}, numpy {m.get('numpy', '?')}, embreex {m.get('embreex', '?')}, ZeroMQ {m.get('zmq', '?')}; "
             f"load average at start {m.get('load_average', '?')} (other jobs shared this machine: every ratio below "
             "compares things measured in the same run, interleaved where it matters). Full run: "
             f"{doc.get('elapsed_s', 0):.0f} s. Machine-readable results: [`benchmarks.json`](benchmarks.json).\n")
    again = [f"`{name}` ({s.get('measured_at', '?')} on {s['machine'].get('cpu', '?')})"
             for name in ORDER if (s := doc.get("sections", {}).get(name)) and s.get("machine")
             and s["machine"].get("cpu") != m.get("cpu")]
    if again:      # `--only` runs on another machine: compare within a section, not across them
        L.append(f"Sections measured again since on another machine: {', '.join(again)}; compare figures "
                 "within one section (its ratios), not across sections.\n")
    if "plots_note" in doc:
        L.append(f"_{doc['plots_note']}_\n")
    secs = doc.get("sections", {})
    if doc.get("plots", {}).get("headline"):
        L.append(f"![Rays per second on the same scene and rays]({doc['plots']['headline']})\n")
    # targets
    targets = [(name, t) for name in ORDER if name in secs for t in secs[name].get("targets", [])]
    if targets:
        L.append("## Targets\n")
        L.append("| target | goal | measured | verdict | how much and why |")
        L.append("|---|---|---|---|---|")
        for _, t in targets:
            L.append(f"| {_cell(t['name'])} | {_cell(t['target'])} | {_cell(t['measured'])} | {_verdict(t['ok'])} | {_cell(t['why'])} |")
        L.append("")
    findings = [(name, f) for name in ORDER if name in secs for f in secs[name].get("findings", [])]
    if findings:
        L.append("## Findings\n")
        for _, f in findings:
            L.append(f"* {f}")
        L.append("")
    if doc.get("bottlenecks"):
        L.append("## Where the time goes\n")
        for b in doc["bottlenecks"]:
            L.append(f"* {b}")
        L.append("")
    for name in ORDER:
        if name not in secs:
            continue
        s = secs[name]
        L.append(f"## {s['title']}\n")
        meta = f"_Section `{name}`: measured {s.get('measured_at', '?')}"
        if s.get("machine") and s["machine"].get("cpu") != m.get("cpu"):
            meta += f" on {s['machine'].get('cpu', '?')}"
        meta += f" in {s.get('elapsed_s', 0):.0f} s" + (" (quick run)" if s.get("quick") else "") + "._\n"
        L.append(meta)
        if s.get("intro"):
            L.append(s["intro"] + "\n")
        plots = {p["id"]: p for p in s.get("plots", [])}
        for t in s.get("tables", []):
            L.append(f"### {t['title']}\n")
            L.append("| " + " | ".join(_cell(c) for c in t["columns"]) + " |")
            L.append("|" + "---|" * len(t["columns"]))
            for r in t["rows"]:
                L.append("| " + " | ".join(_cell(c) for c in r) + " |")
            L.append("")
            for n in t.get("notes", []):
                L.append(f"* {n}")
            if t.get("notes"):
                L.append("")
            key = f"{name}_{t['id']}"
            if t["id"] in plots and key in doc.get("plots", {}):
                L.append(f"![{plots[t['id']]['title']}]({doc['plots'][key]})\n")
        for pid, p in plots.items():           # plots without a table of the same id
            key = f"{name}_{pid}"
            if pid not in {t["id"] for t in s.get("tables", [])} and key in doc.get("plots", {}):
                L.append(f"![{p['title']}]({doc['plots'][key]})\n")
    return "\n".join(L).rstrip() + "\n"
