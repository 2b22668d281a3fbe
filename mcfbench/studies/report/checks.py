"""The figures of the report checked against the paper's captions: every claim of a caption
(panels, statuses, the T-vertices) against the figure's record and frames."""

from pathlib import Path

from mcfbench.running.schemes import get_scheme
from mcfbench.storage.frames import load_frames, surface_points
from mcfbench.studies.convergence.tables import label
from mcfbench.studies.report.inputs import (
    SNAKEMAKE,
    ReportError,
    display_path,
    read_json,
    rel,
)


def _run_sizes(folder, keys):
    """``{run key: n_V}`` of a figure's runs (F- plus T-vertices) from the frames
    files in ``folder`` (``<key>.npz``, :mod:`mcfbench.storage.frames`); a run
    without its file is left out."""
    sizes = {}
    for key in keys:
        path = Path(folder) / f"{key}.npz"
        if path.is_file():
            vertices, extra = surface_points(load_frames(path))
            sizes[key] = len(vertices[0]) + (0 if extra is None else len(extra[0]))
    return sizes


def _claim_verdict(check, runs, last_panel):
    """Evaluate a caption's ``check`` on the DDFV runs of a figure.

    Returns ``(ok or None, text)``.
    """
    ddfv = [r for r in runs if r["family"] == "ddfv" and r["last_step"] is not None]
    if not ddfv:
        return None, "no run record"
    firsts = [r["first_violation"] for r in ddfv]
    steps = max(r["last_step"] for r in ddfv)
    found = [f for f in firsts if f is not None]
    first = min(found) if found else None
    where = (f"first violation at n = {first}" if first is not None
             else f"no violation in {steps} steps")
    if check is None:
        return None, where
    if check == "none":
        ok = first is None and all(r["status"] == "ok" for r in ddfv)
        return ok, where
    if check == "after_last_panel":
        ok = first is not None and first > last_panel
        return ok, f"{where} (last panel n = {last_panel})"
    if check == "by_last_panel":
        ok = first is not None and first <= last_panel
        return ok, f"{where} (last panel n = {last_panel})"
    raise ReportError(f"captions.yaml: unknown check {check!r} "
                      "(none, after_last_panel, by_last_panel or null)")


def figures(sources, captions, experiments):
    """One dict per figure: images, captions (the paper's and ours), the
    runs of its record and the comparison of what the paper states."""
    results, out = sources.results, sources.out
    root = results.parent
    names = list(sources.figures) if sources.figures is not None else list(experiments)
    # each side-by-side comparison right after the paper's figure it extends
    order = {n: i for i, n in enumerate(names)}
    names.sort(key=lambda n: (order.get(n.replace("_cotan", ""), order[n]), n != n.replace(
        "_cotan", "")))
    items = []
    for name in names:
        experiment = experiments[name]
        png = results / "figures" / f"{name}.png"
        diag = results / "diagnostics" / f"{name}.png"
        record_path = results / "runs" / "figures" / f"{name}.json"
        record = read_json(record_path)
        sizes = _run_sizes(results / "runs" / "figures" / name,
                           [run.key for run in experiment.runs])
        runs = []
        for run in experiment.runs:
            rec = (record or {}).get("runs", {}).get(run.key)
            runs.append({
                "key": run.key, "scheme": run.scheme, "label": run.label or run.key,
                "tau": run.tau, "steps": run.steps, "family": get_scheme(run.scheme).family,
                "scheme_label": label(run.scheme),
                "n_V": sizes.get(run.key),
                "status": rec["status"] if rec else None,
                "message": rec.get("message", "") if rec else "",
                "last_step": rec["last_step"] if rec else None,
                "first_violation": rec.get("first_violation") if rec else None,
                "violation": rec.get("violation", "") if rec else "",
                "iterations": rec.get("iterations") if rec else None,
                "wall_seconds": rec.get("wall_seconds") if rec else None,
            })
        panels = [s.step for s in experiment.shots]
        base = name.replace("_cotan", "")
        cap = captions.get(name) or {}
        item = {
            "name": name, "title": experiment.title, "caption": experiment.caption,
            "paper_figure": name in captions, "base": base,
            "number": cap.get("number") or (captions.get(base) or {}).get("number"),
            "paper_caption": cap.get("caption"), "claim": cap.get("claim"),
            "png": rel(png, out) if png.is_file() else None,
            "png_path": display_path(png, root),
            "diagnostics": rel(diag, out) if diag.is_file() else None,
            "record": display_path(record_path, root) if record else None,
            "status": record.get("status") if record else None,
            "seconds": (record or {}).get("seconds", {}).get("total"),
            "provenance": (record or {}).get("provenance"),
            "runs": runs, "panels": panels,
            "target": f"{SNAKEMAKE} {display_path(png, root)}",
            "rows": [],
        }
        if cap:
            ddfv = [r for r in runs if r["family"] == "ddfv"]
            ours_nv = [r["n_V"] for r in ddfv]
            ours_tau = sorted({r["tau"] for r in ddfv})
            rows = []
            if cap.get("n_V") is not None:
                rows.append({"what": "n_V", "paper": cap["n_V"], "ours": ours_nv,
                             "ok": list(cap["n_V"]) == ours_nv})
            else:
                rows.append({"what": "n_V", "paper": None, "ours": ours_nv, "ok": None})
            if cap.get("tau") is not None:
                rows.append({"what": "τ", "paper": [cap["tau"]], "ours": ours_tau,
                             "ok": ours_tau == [float(cap["tau"])]})
            elif any(r["steps"] for r in ddfv):
                rows.append({"what": "τ", "paper": None, "ours": ours_tau, "ok": None})
            if cap.get("steps") is not None:
                rows.append({"what": "time levels", "paper": cap["steps"], "ours": panels,
                             "ok": list(cap["steps"]) == panels})
            else:
                rows.append({"what": "time levels", "paper": None, "ours": panels,
                             "ok": None})
            if cap.get("claim"):
                ok, text = _claim_verdict(cap.get("check"), runs, max(panels))
                rows.append({"what": "behaviour", "paper": cap["claim"], "ours": text,
                             "ok": ok})
            item["rows"] = rows
        items.append(item)
    return items
