"""lrcal.report's calibration page: DIR/report.html for `lrcal identify ... --report DIR`: a self-contained page (figures
embedded as PNG, also written as PNG and SVG in DIR/figures/) from what identify wrote in
DIR/calibration.json (SI units; the page shows mm and mrad and says so). It never recomputes the
calibration: every number comes from the JSON.

    python3 -m lrcal.report --calibration DIR

Sections: the fit check, residuals per configuration, the parameters with their change and
uncertainty, the correlation map, identifiability, cross-validation, the predicted accuracy over
the workspace and the calibrated files. Exit code 2 (with a message naming the file) for a
missing or malformed calibration.json, 5 when the page cannot be written.
"""
import html
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .page import CHECK, STYLE, figure_html, write_atomically  # noqa: E402


class CalibrationDataError(Exception):
    """calibration.json is missing or lacks what the page needs."""


ANGULAR = ("theta", "alpha", "beta")


def is_angular(name):
    return name.startswith(ANGULAR) or (name.startswith("plane") and "_u" in name)


def display(name, value):
    """(value in the table's unit, unit): mm for lengths, mrad for angles, ppm for the scale."""
    if name == "ranger_scale":
        return value * 1e6, "ppm"
    return value * 1e3, ("mrad" if is_angular(name) else "mm")


def load(folder):
    path = os.path.join(folder, "calibration.json")
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError) as e:
        raise CalibrationDataError(f"{path}: expected the JSON that lrcal identify --report "
                                   f"writes ({e})")
    for key in ("parameters", "termination", "n_configurations"):
        if key not in data:
            raise CalibrationDataError(f"{path}: missing key '{key}'")
    return data


def save(fig, fig_dir, name, caption, out):
    os.makedirs(fig_dir, exist_ok=True)
    png = os.path.join(fig_dir, name + ".png")
    fig.savefig(png, dpi=110, bbox_inches="tight")
    fig.savefig(os.path.join(fig_dir, name + ".svg"), bbox_inches="tight")
    plt.close(fig)
    out.append((png, caption))


def residual_figure(data, fig_dir, out):
    z = data.get("fit", {}).get("standardized_residuals") or []
    if not z:
        return
    given = data.get("sigma_given") is not None
    fig, ax = plt.subplots(figsize=(10, 3.2))
    x = np.arange(1, len(z) + 1)
    ax.bar(x, z, color=["#c0392b" if abs(v) > 4 else "#4a7ab5" for v in z])
    for level in (-4, 4):
        ax.axhline(level, color="#c0392b", lw=0.8, ls="--")
    k = data.get("values_per_configuration") or 1
    ax.set_xlabel("configuration (1-based, data order)" if k == 1 else
                  f"value (1-based, data order: {k} per configuration)")
    ax.set_ylabel("standardized residual")
    save(fig, fig_dir, "residuals",
         "Standardized residual of each configuration's mean reading (residual over "
         + ("the given σ/√R" if given else "σ̂/√R") + "); beyond ±4 (red) are suspects.", out)


def parameter_figure(data, fig_dir, out):
    params = data["parameters"]
    if not params:
        return
    rows = []
    for p in params:
        std = p["std_given_sigma"] if p.get("std_given_sigma") is not None else p.get("std")
        value, unit = display(p["name"], p["delta"])
        err = display(p["name"], std)[0] if std is not None else 0.0
        rows.append((p["name"], value, err, unit))
    units = sorted({r[3] for r in rows})
    # constrained layout keeps each panel's rotated names clear of the panel below; a panel with
    # few parameters keeps them near its centre rather than spread over the whole width.
    fig, axes = plt.subplots(len(units), 1, figsize=(10, 3.3 * len(units)), squeeze=False,
                             layout="constrained")
    for ax, unit in zip(axes[:, 0], units):
        sel = [r for r in rows if r[3] == unit]
        x = np.arange(len(sel))
        ax.errorbar(x, [r[1] for r in sel], yerr=[2 * r[2] for r in sel], fmt="o", capsize=3)
        ax.axhline(0, color="#888", lw=0.8)
        ax.set_xticks(x)
        ax.set_xticklabels([r[0] for r in sel], rotation=60, fontsize=8, ha="right",
                           rotation_mode="anchor")
        ax.set_xlim(-0.5 - max(0, (8 - len(sel)) / 2), len(sel) - 0.5 + max(0, (8 - len(sel)) / 2))
        ax.set_ylabel(f"change ({unit})")
    save(fig, fig_dir, "parameters",
         "Identified change of each parameter from its nominal value, with ±2 standard "
         "deviations (given σ when stated, else residual-based); mm, mrad, ppm.", out)


def correlation_figure(data, fig_dir, out):
    corr = data.get("correlation")
    if not corr:
        return
    names = [p["name"] for p in data["parameters"]]
    fig, ax = plt.subplots(figsize=(7.5, 6.5))
    im = ax.imshow(np.array(corr), vmin=-1, vmax=1, cmap="RdBu_r")
    ax.set_xticks(range(len(names)))
    ax.set_yticks(range(len(names)))
    ax.set_xticklabels(names, rotation=90, fontsize=7)
    ax.set_yticklabels(names, fontsize=7)
    fig.colorbar(im, ax=ax, label="correlation")
    save(fig, fig_dir, "correlation", "Correlation of the identified parameters.", out)


def holdout_figure(data, fig_dir, out):
    h = data.get("holdout")
    if not h or not h.get("predictions"):
        return
    preds = h["predictions"]
    fig, ax = plt.subplots(figsize=(10, 3.2))
    ax.scatter([p["configuration"] for p in preds], [p["z"] for p in preds], s=12,
               c=[p["fold"] for p in preds], cmap="tab10")
    for level in (-4, 4):
        ax.axhline(level, color="#c0392b", lw=0.8, ls="--")
    ax.set_xlabel("held-out configuration (1-based; colour: fold)")
    ax.set_ylabel("error / predicted std")
    save(fig, fig_dir, "holdout",
         f"Cross-validation, {h['folds']} folds: each configuration's held-out error over the "
         "fit's own prediction of its standard deviation (about N(0, 1) when the model and σ are "
         "right).", out)


def accuracy_figure(data, fig_dir, out):
    acc = data.get("workspace_accuracy")
    if not acc or not acc.get("poses"):
        return
    radius = np.array([p["position_radius_95"] for p in acc["poses"]]) * 1e3
    total = np.array([p.get("position_radius_95_total", p["position_radius_95"])
                      for p in acc["poses"]]) * 1e3
    fig, ax = plt.subplots(figsize=(7, 3.2))
    bins = np.linspace(0, max(total.max(), radius.max()) * 1.02 + 1e-12, 40)
    ax.hist(radius, bins=bins, color="#9db4d6", label="reading noise only (data part)")
    ax.hist(total, bins=bins, color="#4a7ab5", alpha=0.8,
            label="total (with the terms held at nominal)")
    ax.axvline(acc.get("p95_position_radius_95_total", acc["p95_position_radius_95"]) * 1e3,
               color="#c0392b", lw=1, label="95th percentile of the total")
    ax.set_xlabel("radius holding the position error with 95 % probability (mm)")
    ax.set_ylabel("poses")
    ax.legend(fontsize=8)
    save(fig, fig_dir, "accuracy",
         f"Predicted accuracy of the calibrated arm at {len(radius)} poses drawn over the joint "
         "ranges (first-order propagation): from the reading noise alone, and in total with "
         "everything the calibration did not estimate, each from its tolerance.", out)


def fit_text(data):
    fit = data.get("fit") or {}
    parts = [f"Termination: <b>{html.escape(data['termination'])}</b> "
             f"({html.escape(data.get('solver', ''))}, {html.escape(data.get('loss', ''))}), "
             f"{data['n_configurations']} configurations, {len(data['parameters'])} parameters, "
             f"residual RMS {data.get('residual_rms', 0) * 1e3:.4f} mm."]
    if data.get("message"):
        parts.append(html.escape(data["message"]))
    if fit.get("test") == "robust_scale" and fit.get("robust_p_value") is not None:
        verdict = ("consistent with the stated noise" if fit.get("consistent")
                   else "<b>INCONSISTENT with the stated noise</b>: σ too small, an unmodelled "
                   "error (a second plane, a ranger offset or scale) or wrong units")
        parts.append(f"Robust fit check: the residuals' robust scale (1.4826 × median |z|) is "
                     f"{fit['robust_scale']:.3f} of the stated σ, p = "
                     f"{fit['robust_p_value']:.3g}: {verdict}. χ² = {fit['chi2']:.2f} on "
                     f"{fit['dof']} degrees of freedom is not the test with a robust loss.")
    elif fit.get("chi2") is not None:
        verdict = ("consistent with the stated noise" if fit.get("consistent")
                   else "<b>INCONSISTENT with the stated noise</b>: σ too small, an unmodelled "
                   "error (a second plane, a ranger offset or scale), wrong units or outliers")
        parts.append(f"χ² = {fit['chi2']:.2f} on {fit['dof']} degrees of freedom, "
                     f"p = {fit['p_value']:.3g}: {verdict}.")
    elif data.get("sigma_hat") is not None:
        parts.append(f"No σ given: σ̂ per reading {data['sigma_hat'] * 1e3:.4f} mm.")
    if fit.get("suspects"):
        labels = fit.get("suspect_labels") or [None] * len(fit["suspects"])
        parts.append("Suspect configurations (beyond 4 σ): " + ", ".join(
            str(i) if label is None else f"{i} ({html.escape(label)})"
            for i, label in zip(fit["suspects"], labels)) + ".")
    return "<p>" + "</p><p>".join(parts) + "</p>"


def value_text(name, value):
    """A nominal value or estimate as users read a D-H table: angles in degrees, lengths in mm,
    the ranger's scale in ppm."""
    if name == "ranger_scale":
        return f"{value * 1e6:.4f} ppm"
    if is_angular(name):
        return f"{np.degrees(value):.6f}°"
    return f"{value * 1e3:.4f} mm"


def parameter_table(data):
    rows = ["<table><tr><th>parameter</th><th>nominal</th><th>estimate</th>"
            "<th>change</th><th>std</th><th>unit of change and std</th></tr>"]
    for p in data["parameters"]:
        std = p["std_given_sigma"] if p.get("std_given_sigma") is not None else p.get("std")
        delta, unit = display(p["name"], p["delta"])
        rows.append("<tr>" + "".join(f"<td>{c}</td>" for c in (
            html.escape(p["name"]), value_text(p["name"], p["nominal"]),
            value_text(p["name"], p["estimate"]), f"{delta:.4f}",
            "undefined" if std is None else f"{display(p['name'], std)[0]:.4f}", unit)) + "</tr>")
    rows.append("</table>")
    return "".join(rows)


def before_after_table(data):
    """The readings against the nominal model (before) and the calibrated one (after): the RMS of
    √R·(h̄ − h) over the configurations, about σ for a model that explains the readings."""
    # A kind of several values per configuration (a tracker's point or pose, a scanner's
    # beams): the RMS is over its values, an orientation weighed as σ/σ_angle of a length.
    m = data.get("n_values") or data.get("n_configurations") or 0
    if not m or data.get("initial_cost") is None or data.get("final_cost") is None:
        return ""
    before = np.sqrt(2 * data["initial_cost"] / m) * 1e3
    after = np.sqrt(2 * data["final_cost"] / m) * 1e3
    sigma = data.get("sigma_given")
    label = ("RMS of √w·(y − ŷ) over the values (mm; an angle weighed as σ/σ_angle)"
             if data.get("n_values") else "RMS of √R·(h̄ − h) (mm)")
    rows = [f"<table><tr><th>model</th><th>{label}</th>"
            + ("<th>over the stated σ</th>" if sigma else "") + "</tr>"]
    for label, value in (("nominal (before)", before), ("calibrated (after)", after)):
        rows.append(f"<tr><td>{label}</td><td>{value:.4f}</td>"
                    + (f"<td>{value / (sigma * 1e3):.2f}</td>" if sigma else "") + "</tr>")
    rows.append("</table>")
    return ("<p>How well each model explains the readings (R readings averaged per configuration; "
            "the calibrated model's value is about σ when it explains them). The arm's pose "
            "accuracy before calibration is not known from these readings: the section "
            "below states the calibrated arm's.</p>" + "".join(rows))


def identifiability_text(data):
    ident = data.get("identifiability") or {}
    text = (f"<p>Rank {ident.get('rank', '?')} of {ident.get('n_params', '?')} parameters "
            f"at the nominal model.")
    if data.get("fixed_for_rank"):
        text += " Fixed for rank deficiency: " + ", ".join(data["fixed_for_rank"]) + "."
    for dep in ident.get("dependencies", []):
        text += "<br>Dependence: " + html.escape(" ".join(
            f"{t['coefficient']:+.4g}·{t['name']}" for t in dep))
    return text + "</p>"


def holdout_text(data):
    h = data.get("holdout")
    if not h:
        return "<p>Not run (fewer than two configurations per fold).</p>"
    if not h.get("predictions"):
        return ("<p>No fold could be fitted without its configurations: "
                + html.escape("; ".join(f["reason"] for f in h.get("failed_folds", []))) + "</p>")
    verdict = ("held-out readings are predicted as well as the fit says" if h["consistent"]
               else "<b>held-out readings are predicted worse than the fit says</b>")
    return (f"<p>{h['folds']} folds (configuration i in fold i mod K): held-out error RMS "
            f"{h['rms_error'] * 1e3:.4f} mm, predicted {h['rms_predicted'] * 1e3:.4f} mm "
            f"(ratio {h['ratio']:.3f}); mean z² {h['mean_z2']:.3f} (1 ± "
            f"{h['mean_z2_tolerance']:.3f} expected): {verdict}.</p>")


def accuracy_text(data):
    acc = data.get("workspace_accuracy")
    if not acc:
        return "<p>Not available: the covariance is undefined (give --sigma-mm).</p>"
    text = (f"<p>Over {len(acc['poses'])} poses drawn over the joint ranges: RMS position error "
            f"<b>{acc.get('rms_position_total', acc['rms_position']) * 1e3:.4f} mm in total</b> "
            f"({acc['rms_position'] * 1e3:.4f} mm from the reading noise alone); 95th percentile "
            f"of the total 95 % radius "
            f"{acc.get('p95_position_radius_95_total', acc['p95_position_radius_95']) * 1e3:.4f} mm"
            f"; worst pose (data part) {acc['worst']}.</p>")
    used = acc.get("sigma_used")
    if used:
        text += (f"<p>σ of one reading used: {used['sigma'] * 1e3:.4f} mm "
                 f"({html.escape(used['reason'])}).</p>")
    sources = acc.get("sources") or []
    if sources:
        rows = "".join(
            f"<tr><td>{html.escape(s['name'])}</td>"
            f"<td>{'' if s['prior_sigma'] is None else html.escape(prior_text(s))}</td>"
            f"<td>{html.escape(s['absorbed_by'] or ('-' if s['prior_sigma'] is None else 'not seen'))}</td>"
            f"<td>{s['position_rms'] * 1e3:.4f}</td><td>{s['orientation_rms'] * 1e3:.4f}</td>"
            f"<td>{s['share'] * 100:.1f} %</td></tr>" for s in sources)
        text += ("<table><tr><th>source</th><th>prior</th><th>absorbed by</th>"
                 "<th>position RMS (mm)</th><th>orientation RMS (mrad)</th><th>share</th></tr>"
                 + rows + "</table>")
    if acc.get("defaulted"):
        text += ("<p><b>Warning:</b> no tolerance was known for "
                 + html.escape(", ".join(acc["defaulted"]))
                 + "; lrcal's stated defaults (" + html.escape(acc.get("defaults", ""))
                 + ") were used. Give them in the robot file's <code>tolerances:</code>.</p>")
    if acc.get("taken_as_exact"):
        text += ("<p><b>Taken as exact</b> (not estimated, no tolerance given): "
                 + html.escape(", ".join(acc["taken_as_exact"]))
                 + ". Give <code>tolerances.base</code> / <code>tolerances.tool</code> in the "
                 "robot file if the base frame is not the robot's own.</p>")
    return text


def measured_text(data):
    m = data.get("measured_points")
    if not m:
        return ("<p>None given (identify --measured FILE with --report: points a tracker "
                "measured, not used in the fit).</p>")
    xyz = m["instrument"]["xyz"]
    rows = "".join(
        f"<tr><td>{i + 1}</td><td>{e[0] * 1e3:.4f}</td><td>{e[1] * 1e3:.4f}</td>"
        f"<td>{e[2] * 1e3:.4f}</td><td>{sum(c * c for c in e) ** 0.5 * 1e3:.4f}</td></tr>"
        for i, e in enumerate(m["errors"][:50]))
    more = (f"<p>The first 50 of {len(m['errors'])} points; calibration.json has them all.</p>"
            if len(m["errors"]) > 50 else "")
    return (f"<p><code>{html.escape(str(m.get('file', '?')))}</code>: {m['points']} points a "
            f"tracker measured, not used in the fit. With the instrument registered (its frame "
            f"at ({xyz[0]:.4f}, {xyz[1]:.4f}, {xyz[2]:.4f}) m in the base frame; "
            f"{len(m['registered'])} terms: {html.escape(', '.join(m['registered']))}), the "
            f"calibrated model's error is <b>{m['rms'] * 1e3:.4f} mm RMS</b>, worst "
            f"{m['worst'] * 1e3:.4f} mm at point {m['worst_point']}.</p>"
            "<table><tr><th>point</th><th>x (mm)</th><th>y (mm)</th><th>z (mm)</th>"
            "<th>|error| (mm)</th></tr>" + rows + "</table>" + more)


def prior_text(source):
    name, sigma = source["name"], source["prior_sigma"]
    if name == "ranger_scale":
        value = f"{sigma * 1e6:.1f} ppm"
    elif name.startswith(("theta", "alpha", "beta")) or "_u" in name:
        value = f"{sigma * 1e3:.3f} mrad"
    else:
        value = f"{sigma * 1e3:.3f} mm"
    return value + (" (default)" if source["defaulted"] else "")


def build(folder):
    data = load(folder)
    fig_dir = os.path.join(folder, "figures")
    figures = []
    for make in (residual_figure, parameter_figure, correlation_figure, holdout_figure,
                 accuracy_figure):
        make(data, fig_dir, figures)
    parts = ["<!DOCTYPE html><html><head><meta charset='utf-8'>",
             "<title>lrcal calibration report</title>", f"<style>{STYLE}</style></head><body>",
             "<h1>Calibration report</h1>",
             f"<p>Robot <code>{html.escape(str(data.get('robot', '?')))}</code>, data "
             f"<code>{html.escape(str(data.get('data', {}).get('file', '?')))}</code>. Lengths "
             "in mm, angles in mrad (nominal values and estimates of angles in degrees); "
             "calibration.json has every number in SI.</p>",
             "<h2>Fit check</h2>", fit_text(data),
             "<h2>Before and after</h2>", before_after_table(data),
             "<h2>Parameters</h2>", parameter_table(data),
             "<h2>Identifiability</h2>", identifiability_text(data),
             "<h2>Cross-validation</h2>", holdout_text(data),
             "<h2>Accuracy over the workspace</h2>", accuracy_text(data),
             "<h2>Measured points</h2>", measured_text(data), "<h2>Figures</h2>"]
    parts.extend(figure_html(png, caption, folder) for png, caption in figures)
    parts.append("<h2>Calibrated files</h2>")
    if data.get("calibrated_robot"):
        name = html.escape(data["calibrated_robot"])
        urdf = html.escape(data.get("calibrated_urdf", ""))
        urdf_text = (f"<a href='{urdf}'>{urdf}</a>: the same model as URDF (lrcal export); "
                     if urdf else "")
        parts.append(f"<p><a href='{name}'>{name}</a>: the calibrated robot file (every lrcal "
                     f"command takes it as --robot); {urdf_text}<a href='calibration.json'>"
                     "calibration.json</a>: everything on this page in SI.</p>")
    else:
        parts.append("<p>None: the fit is not usable.</p>")
    parts.append(f"<script>{CHECK}</script></body></html>")
    path = os.path.join(folder, "report.html")
    write_atomically(path, "\n".join(parts))
    write_atomically(os.path.join(folder, "figures.json"),
                     json.dumps({"figures": [os.path.basename(p) for p, _ in figures],
                                 "captions": [c for _, c in figures]}, indent=2))
    return path, figures
