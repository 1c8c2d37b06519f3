"""lrcal.report's figures of a study run, from what `lrcal run` and `lrcal report` wrote (never
recomputing the science): RUN_DIR/manifest.json and RUN_DIR/report/{tables/*, document.json,
trials.snapshot.sqlite (removed by `lrcal report` once the figures are drawn), realisation.json,
status.json}. The trials are read by lrcal.load_run's reader (lrcal.Run), from the snapshot the
tables were made of. Units as in the tables: mm and mrad, named on every axis.

Uses Debian's python3-pandas, python3-numpy and python3-matplotlib.
"""
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
import pandas as pd  # noqa: E402

from .._run import Run as _StoredRun  # noqa: E402
from .._run import _display_column  # noqa: E402

AXES = ("x", "y", "z")
METRICS = (("rms_pos", "RMS position error (mm)"), ("rms_ori", "RMS orientation error (mrad)"),
           ("max_pos", "max position error (mm)"), ("max_ori", "max orientation error (mrad)"))
MAX_CELLS_PER_FIGURE = 12


def _column(metric, axis):
    """The trial table's column of a validation metric of the identified model (mm or mrad):
    load_run's name for the store's column."""
    return _display_column(f"val_{metric}_{axis}")[0]


class RunDataError(Exception):
    """A run directory that is missing or malformed: the message says what was expected."""


class Run:
    """Everything a report needs, loaded from a run directory prepared by `lrcal report`: the
    manifest, report/tables/*, report/document.json (summary.md as blocks), report/status.json,
    report/realisation.json and the trials of report/trials.snapshot.sqlite."""

    def __init__(self, run_dir):
        self.dir = run_dir
        self.report_dir = os.path.join(run_dir, "report")
        if not os.path.isdir(run_dir):
            raise RunDataError(f"{run_dir}: no such run directory")
        self.manifest = self._json(os.path.join(run_dir, "manifest.json"))
        tables = os.path.join(self.report_dir, "tables")
        self.summary = self._json(os.path.join(tables, "summary.json"))
        self.status = self._json(os.path.join(self.report_dir, "status.json"))
        self.validation = self._csv(os.path.join(tables, "validation.csv"))
        self.parameters = self._csv(os.path.join(tables, "parameters.csv"))
        self.cells_table = self._csv(os.path.join(tables, "cells.csv"))
        placement = os.path.join(tables, "paper_placement.csv")
        self.placement = pd.read_csv(placement, na_values=["—"]) if os.path.exists(placement) else None
        realisation = os.path.join(self.report_dir, "realisation.json")
        self.realisation = self._json(realisation) if os.path.exists(realisation) else None
        self.snapshot = os.path.join(self.report_dir, "trials.snapshot.sqlite")
        self.document = self._json(os.path.join(self.report_dir, "document.json"))
        if not isinstance(self.document.get("blocks"), list):
            raise RunDataError(f"{self.report_dir}/document.json: 'blocks' should be a list")
        self.cells = self.summary.get("cells", [])
        if not isinstance(self.cells, list):
            raise RunDataError(f"{tables}/summary.json: 'cells' should be a list")

    @staticmethod
    def _json(path):
        if not os.path.exists(path):
            raise RunDataError(f"{path}: missing (run `lrcal report RUN_DIR`, which prepares it)")
        try:
            with open(path, encoding="utf-8") as f:
                return json.load(f)
        except json.JSONDecodeError as e:
            raise RunDataError(f"{path}: not valid JSON ({e})") from e

    @staticmethod
    def _csv(path):
        if not os.path.exists(path):
            raise RunDataError(f"{path}: missing (run `lrcal report RUN_DIR`, which prepares it)")
        try:
            # "—" marks a value that does not exist yet (a cell with no trials in a partial run).
            return pd.read_csv(path, na_values=["—"])
        except Exception as e:  # pandas raises several kinds
            raise RunDataError(f"{path}: not a readable CSV ({e})") from e

    def trial_metrics(self):
        """One row per ok trial the tables use, of the cells the figures draw (shown_cells):
        cell_id, trial and the identified model's validation metrics (under stop_when, only the
        trials before each cell's stopping point)."""
        if not os.path.isfile(self.snapshot):
            raise RunDataError(f"{self.snapshot}: missing (run `lrcal report RUN_DIR`, which "
                               "prepares it)")
        stored = _StoredRun(self.dir, True, stores=[self.snapshot])
        # Only the cells the figures draw are read (a large study's chosen few).
        frames = [stored.trials_of(c["id"]) for c in self.shown_cells()]
        trials = pd.concat(frames, ignore_index=True) if frames else stored.trials
        columns = [_column(m, a) for m, _ in METRICS for a in AXES]
        data = trials.loc[trials["status"] == "ok", ["cell_id", "trial"] + columns]
        data = data.sort_values(["cell_id", "trial"]).reset_index(drop=True)
        used = {c["id"]: c["stop"]["trials_used"] for c in self.cells if "stop" in c}
        if used:
            limit = data["cell_id"].map(used).fillna(np.inf)
            data = data[data["trial"] < limit]
        return data

    def chosen_cells(self):
        """The cells the summary's per-cell tables show (summary.json's shown_cells: every cell
        of a small study; of a large one the paper's and those at the minimum, quartiles and
        maximum of the mean RMS position error), in study order."""
        ids = self.summary.get("shown_cells")
        if not isinstance(ids, list):
            return list(self.cells)
        chosen = set(ids)
        return [c for c in self.cells if c["id"] in chosen]

    def shown_cells(self, limit=MAX_CELLS_PER_FIGURE):
        """The chosen cells, paper cells first, at most `limit`."""
        chosen = self.chosen_cells()
        paper = [c for c in chosen if c["settings"].get("paper_case", 0)]
        rest = [c for c in chosen if not c["settings"].get("paper_case", 0)]
        return (paper + rest)[:limit]

    def left_out_note(self, shown):
        """What a figure showing `shown` cells says about the others ("" when it shows all)."""
        if len(shown) >= len(self.cells):
            return ""
        chosen = len(self.chosen_cells())
        if chosen < len(self.cells) and len(shown) == chosen:
            return (f" {len(shown)} of the {len(self.cells)} cells are drawn: the paper's and "
                    "those at the minimum, quartiles and maximum of the mean RMS position error "
                    "(the summary's per-cell tables show the same; tables/*.csv have every "
                    "cell).")
        return (f" Only the first {len(shown)} of the {len(self.cells)} cells are drawn "
                "(paper cells first); tables/*.csv have every cell.")

    def parameter_unit(self, cell_id, name):
        """mm or mrad for a parameter, from parameters.csv."""
        rows = self.parameters[(self.parameters["cell_id"] == cell_id) &
                               (self.parameters["parameter"] == name)]
        return str(rows["unit"].iloc[0]) if len(rows) else ("mrad" if name[:1] in "θαβ" else "mm")

    def paper_value(self, cell, metric, axis):
        """The paper's published value for a paper cell, from paper_placement.csv (or None)."""
        case = cell["settings"].get("paper_case", 0)
        if not case or self.placement is None:
            return None
        rows = self.placement[(self.placement["case"] == f"case {case}") &
                              (self.placement["quantity"] == f"validation {metric}") &
                              (self.placement["axis/parameter"] == axis)]
        return float(rows["paper"].iloc[0]) if len(rows) else None


def _save(fig, out_dir, name):
    os.makedirs(out_dir, exist_ok=True)
    png = os.path.join(out_dir, name + ".png")
    fig.savefig(png, dpi=110, bbox_inches="tight")
    fig.savefig(os.path.join(out_dir, name + ".svg"), bbox_inches="tight")
    plt.close(fig)
    return png


def realisation_figures(run, out_dir):
    """The paper's figures from one realisation (trial 0 of each cell)."""
    if not run.realisation:
        return []
    cells = [c for c in run.realisation["cells"] if "distance_error_nominal" in c]
    cells = sorted(cells, key=lambda c: (not c.get("paper_case"), 0))[:4]
    if not cells:
        return []
    out = []
    # Nominal and identified on their own axes: the identified errors are ~100 times smaller and
    # would be invisible on the nominal model's scale.
    fig, axes = plt.subplots(len(cells), 2, figsize=(12, 2.6 * len(cells)), squeeze=False)
    for row, c in zip(axes, cells):
        n = np.arange(1, len(c["distance_error_nominal"]) + 1)
        for ax, key, color, name in ((row[0], "distance_error_nominal", "0.5", "nominal model"),
                                     (row[1], "distance_error_identified", "C0", "identified model")):
            ax.bar(n, c[key], width=0.8, color=color)
            ax.axhline(0, color="k", lw=0.5)
            ax.set_title(f"{c['label']}: {name} (trial 0)", fontsize=9)
            ax.set_xlabel("measurement configuration")
            ax.set_ylabel("h measured − h model (mm)")
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    fig.tight_layout()
    out.append((_save(fig, out_dir, "realisation_distance_errors"),
                "Distance errors in the measurement configurations, nominal model (left) and "
                "identified model (right, on its own scale: about a hundred times smaller), one "
                "realisation, as the paper's first figure." +
                (f" The first {len(cells)} cells with a realisation are drawn."
                 if len(run.realisation["cells"]) > len(cells) else "")))

    fig, axes = plt.subplots(2, 2, figsize=(11, 7))
    for row, (key, title) in enumerate((("measurement", "measurement"), ("validation", "validation"))):
        for col, (what, unit) in enumerate((("position", "mm"), ("orientation", "mrad"))):
            ax = axes[row, col]
            nominal = np.linalg.norm(np.array(cells[0][key][f"{what}_nominal"]), axis=1)
            if key == "validation":
                ax.plot(np.arange(1, len(nominal) + 1), nominal, "o-", color="0.5", label="nominal")
            for i, c in enumerate(cells):
                err = np.linalg.norm(np.array(c[key][f"{what}_identified"]), axis=1)
                if key == "measurement":
                    nom = np.linalg.norm(np.array(c[key][f"{what}_nominal"]), axis=1)
                    ax.plot(np.arange(1, len(nom) + 1), nom, ".", color="0.6", ms=3,
                            label="nominal" if i == 0 else None)
                ax.plot(np.arange(1, len(err) + 1), err, "o-" if key == "validation" else ".-",
                        color=f"C{i}", ms=3, label=c["label"])
            ax.set_yscale("log")
            ax.set_title(f"{what} error, {title} configurations")
            ax.set_xlabel(f"{title} configuration")
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.set_ylabel(f"|error| ({unit})")
            ax.legend(fontsize=7)
    fig.tight_layout()
    out.append((_save(fig, out_dir, "realisation_pose_errors"),
                "Position and orientation errors (norm over x, y, z) per configuration, in the "
                "measurement and the validation configurations (one realisation; log scale)."))
    return out


def _cell_ticks(cells):
    """Tick labels for cells and the axis label that names them. Labels of the form
    "key=value, key=value" with the same keys in every cell become their values alone (numbers
    to 4 significant digits), the keys going to the axis label; other labels are shortened."""
    parts = [[p.partition("=") for p in c["label"].split(", ")] for c in cells]
    keys = [k for k, eq, _ in parts[0]] if parts and all(eq for _, eq, _ in parts[0]) else None
    if keys and all([k for k, eq, _ in p] == keys and all(eq for _, eq, _ in p) for p in parts):
        def value(text):
            try:
                return _short(float(text)) if not text.lstrip("-").isdigit() else text
            except ValueError:
                return _short(text, 16)
        return [", ".join(value(v) for _, _, v in p) for p in parts], ", ".join(keys)
    return [_short(c["label"]) for c in cells], None


def distribution_figure(run, out_dir):
    """Box plots of the validation RMS and max errors per axis for each cell; the paper's
    published values marked for paper cells."""
    data = run.trial_metrics()
    if data.empty:
        return []
    cells = run.shown_cells()
    shown_paper = set()
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5))
    for ax, (metric, title) in zip(axes.flat, METRICS):
        boxes, positions, colors = [], [], []
        any_paper = False
        ticks = []
        for i, cell in enumerate(cells):
            rows = data[data["cell_id"] == cell["id"]]
            for j, axis in enumerate(AXES):
                boxes.append(rows[_column(metric, axis)].to_numpy())
                positions.append(i * 4 + j)
                colors.append(f"C{j}")
                paper = run.paper_value(cell, metric, axis)
                if paper is not None:
                    ax.plot(i * 4 + j, paper, "D", color="red", ms=5,
                            label=None if any_paper else "paper")
                    any_paper = True
                    shown_paper.add(True)
            ticks.append(i * 4 + 1)
        bp = ax.boxplot(boxes, positions=positions, widths=0.8, showfliers=False, patch_artist=True)
        for patch, color in zip(bp["boxes"], colors):
            patch.set_facecolor(color)
            patch.set_alpha(0.5)
        ticklabels, xlabel = _cell_ticks(cells)
        ax.set_xticks(ticks)
        ax.set_xticklabels(ticklabels, rotation=30, ha="right", fontsize=8)
        if xlabel:
            ax.set_xlabel(xlabel, fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel(title)
    # One legend for the four panels, above them: inside a panel it hid the paper's values.
    handles = [plt.Rectangle((0, 0), 1, 1, color=f"C{j}", alpha=0.5) for j in range(3)]
    labels = list(AXES)
    h, l = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles + h, labels + l, fontsize=8, loc="upper center", ncol=len(labels + l),
               bbox_to_anchor=(0.5, 0.955), frameon=False)
    fig.suptitle("Validation errors over the Monte-Carlo trials (boxes: p25–p75, whiskers 1.5 IQR"
                 + ("; red: the paper's published value)" if shown_paper else ")"), fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    return [(_save(fig, out_dir, "distributions_validation"),
             "Distributions of the validation RMS and max errors per base axis over the trials of "
             "each cell." + (" Red diamonds: the paper's published values." if shown_paper else "")
             + run.left_out_note(cells))]


def _short(value, width=28):
    """A setting's value for a label: numbers to 4 significant digits (0.30000000000000004 is
    0.3), text cut to `width` characters."""
    if isinstance(value, float):
        return f"{value:.4g}"
    text = str(value)
    return text if len(text) <= width else text[:width - 1] + "…"


def _axis_values(run, cell, axis_index, key, n_axes):
    """The value of sweep axis `key` for a cell: the setting when it is a number, else the
    cell's label part for that axis."""
    value = cell["settings"]
    if key != ".":
        for part in key.split("."):
            value = value.get(part) if isinstance(value, dict) else None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return value, True
    parts = cell["label"].split(", ")
    return (parts[axis_index] if len(parts) == n_axes else cell["label"]), False


def _other_axes_label(run, cell, a, axes_spec):
    """The cell's values of every sweep axis but `a`, each named by its key: a line's label."""
    parts = []
    for b, spec in enumerate(axes_spec):
        if b == a:
            continue
        key = spec.get("key", "?")
        value = _short(_axis_values(run, cell, b, key, len(axes_spec))[0])
        parts.append(value if key == "." else f"{key}={value}")
    return ", ".join(parts)


def sensitivity_figures(run, out_dir):
    """One figure per sweep axis: validation RMS position and orientation (mean over the x, y, z
    axes of each axis' mean, p5 and p95) against the axis, one line per value of the others."""
    axes_spec = (run.summary.get("study", {}).get("sweep") or {}).get("axes", [])
    if not axes_spec:
        return []
    val = run.validation[run.validation["model"] == "identified"]
    n_axes = len(axes_spec)
    out = []
    for a, spec in enumerate(axes_spec):
        key = spec.get("key", "?")
        rows = []
        for cell in run.cells:
            x, numeric = _axis_values(run, cell, a, key, n_axes)
            others = _other_axes_label(run, cell, a, axes_spec)
            for metric in ("rms_pos", "rms_ori"):
                r = val[(val["cell_id"] == cell["id"]) & (val["metric"] == metric)]
                if r.empty:
                    continue
                rows.append(dict(x=x, numeric=numeric, group=others, metric=metric,
                                 mean=r["mean"].mean(), p5=r["p5"].mean(), p95=r["p95"].mean()))
        if not rows:
            continue
        df = pd.DataFrame(rows)
        numeric = bool(df["numeric"].all())
        categories = list(dict.fromkeys(df["x"]))
        # "." sweeps whole settings: name the axis by its labels, not by the key.
        name = key if key != "." else "the swept settings (" + ", ".join(
            _short(c, 16) for c in categories) + ")"
        groups = df["group"].nunique()
        # Several other axes: one legend beside the panels (inside, it covered the lines).
        outside = groups > 1
        fig, axs = plt.subplots(1, 2, figsize=(14 if outside else 12,
                                               4.2 + 0.12 * max(0, groups - 12)))
        for ax, (metric, title) in zip(axs, (("rms_pos", "RMS position error (mm)"),
                                             ("rms_ori", "RMS orientation error (mrad)"))):
            for g, (group, sub) in enumerate(df[df["metric"] == metric].groupby("group", sort=False)):
                color = f"C{g % 10}"
                mean, p5, p95 = (sub[c].to_numpy() for c in ("mean", "p5", "p95"))
                if numeric:
                    xs = sub["x"].to_numpy(dtype=float)
                    order = np.argsort(xs)
                    ax.plot(xs[order], mean[order], "o-", color=color, label=group or "mean")
                    ax.fill_between(xs[order], p5[order], p95[order], color=color, alpha=0.15)
                else:
                    # Categories: points with their p5–p95 range, no line between them (the
                    # order of categories means nothing); groups side by side.
                    xs = np.array([categories.index(v) for v in sub["x"]], dtype=float)
                    xs += (g - (groups - 1) / 2) * 0.12
                    ax.errorbar(xs, mean, yerr=[mean - p5, p95 - mean], fmt="o", color=color,
                                capsize=3, label=group or "mean, p5–p95")
            if numeric:
                values = df["x"].astype(float)
                if values.min() > 0 and values.max() / values.min() > 20:
                    ax.set_xscale("log")
                if all(float(v).is_integer() for v in values):
                    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            else:
                ax.set_xticks(range(len(categories)))
                ax.set_xticklabels([_short(c) for c in categories],
                                   rotation=30 if len(categories) > 4 else 0,
                                   ha="right" if len(categories) > 4 else "center", fontsize=8)
                ax.set_xlim(-0.5, len(categories) - 0.5)
            ax.set_yscale("log")
            ax.set_xlabel(key if key != "." else "swept settings")
            ax.set_ylabel(title)
            ax.grid(alpha=0.3)
            if not outside and not numeric:
                ax.legend(fontsize=7)
        if outside:
            h, l = axs[0].get_legend_handles_labels()
            fig.legend(h, l, fontsize=7, loc="upper left", bbox_to_anchor=(0.80, 0.9),
                       title="other settings", title_fontsize=7, frameon=False)
        band = "p5–p95 band" if numeric else "p5–p95 range"
        fig.suptitle(f"Sensitivity to {name}: mean over trials with the {band} "
                     "(averaged over the x, y, z axes)", fontsize=10)
        fig.tight_layout(rect=(0, 0, 0.79 if outside else 1, 1))
        safe = "".join(ch if ch.isalnum() else "_" for ch in key).strip("_") or "settings"
        out.append((_save(fig, out_dir, f"sensitivity_{safe}"),
                    f"Validation accuracy against {name}" +
                    ("." if numeric else ", drawn as categories.")))
    return out


def global_sensitivity_figure(run, out_dir):
    """A study's sensitivity section (Sobol indices with their 95 % bootstrap intervals, or Morris
    mu* against sigma), from summary.json."""
    sens = run.summary.get("sensitivity")
    if not sens or not sens.get("available"):
        return []
    inputs = sens["inputs"]
    keys = [i["key"] for i in inputs]
    metric, unit = sens["metric"], sens["unit"]
    if sens["method"] == "sobol":
        fig, ax = plt.subplots(figsize=(max(6, 1.4 * len(keys) + 2), 4.2))
        xs = np.arange(len(keys))
        for k, (what, label) in enumerate((("first", "first-order S"), ("total", "total T"))):
            est = np.array([i[what][0] for i in inputs])
            low = np.array([i[what][1] for i in inputs])
            high = np.array([i[what][2] for i in inputs])
            ax.bar(xs + (k - 0.5) * 0.38, est, 0.36, color=f"C{k}", label=label,
                   yerr=[est - low, high - est], capsize=3)
        ax.set_xticks(xs)
        ax.set_xticklabels(keys, rotation=20, ha="right", fontsize=8)
        ax.axhline(0, color="k", lw=0.6)
        ax.set_ylabel("share of the variance")
        ax.legend(fontsize=8)
        ax.grid(axis="y", alpha=0.3)
        caption = (f"Sobol indices of the cell mean of {metric} (identified model, x, y, z "
                   "averaged) with their 95 % bootstrap intervals; the noise of the cell means is "
                   f"{100 * sens['noise_variance'] / sens['variance']:.2f} % of the variance.")
        if sens.get("quantity") == "trial":
            share = sens["noise_total"]
            ax.bar([len(keys) + 0.19], [share], 0.36, color="C1")
            ax.set_xticks(list(xs) + [len(keys)])
            ax.set_xticklabels(keys + ["noise (one trial)"], rotation=20, ha="right", fontsize=8)
            caption = (f"Sobol indices of a single calibration's {metric} (one trial; identified "
                       "model, x, y, z averaged), the trial's randomness one more input: its total "
                       f"index {share:.3f}; the inputs' total indices are lower bounds. 95 % "
                       "bootstrap intervals of the inputs' indices.")
    else:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        mu_star = [i["mu_star"] for i in inputs]
        sigma = [i["sigma"] for i in inputs]
        ax.scatter(mu_star, sigma, color="C0")
        for x, y, key in zip(mu_star, sigma, keys):
            ax.annotate(key, (x, y), fontsize=8, xytext=(4, 4), textcoords="offset points")
        ax.set_xlabel(f"mu* ({unit} across the input's range)")
        ax.set_ylabel(f"sigma ({unit})")
        ax.grid(alpha=0.3)
        caption = (f"Morris screening of the cell mean of {metric}: mu* (overall influence) "
                   "against sigma (non-linearity or interactions).")
    fig.suptitle(f"Which inputs matter for {metric}", fontsize=10)
    fig.tight_layout()
    return [(_save(fig, out_dir, "global_sensitivity"), caption)]


def parameter_figures(run, out_dir, limit=4):
    """Empirical against predicted std per parameter, the bias with its Monte-Carlo error bar, and
    the correlation matrix, for the first cells; lengths (mm) and angles (mrad) on their own
    axes."""
    out = []
    shown = run.shown_cells(limit)
    note = run.left_out_note(shown)
    for k, cell in enumerate(shown):
        params = pd.DataFrame(cell["parameters"])
        if params.empty or params["std"].isna().all():
            continue
        params["unit"] = [run.parameter_unit(cell["id"], n) for n in params["name"]]
        units = [u for u in ("mm", "mrad") if (params["unit"] == u).any()]
        fig, axs = plt.subplots(2, len(units), figsize=(13, 6.5), squeeze=False,
                                gridspec_kw={"width_ratios": [max(1, (params["unit"] == u).sum())
                                                              for u in units]})
        for col, unit in enumerate(units):
            sub = params[params["unit"] == unit]
            x = np.arange(len(sub))
            top, bottom = axs[0, col], axs[1, col]
            top.bar(x - 0.2, sub["std"] * 1e3, width=0.4, label="empirical std")
            top.bar(x + 0.2, sub["predicted_std"].astype(float) * 1e3, width=0.4,
                    label="predicted σ·√diag(GᵀWG)⁻¹")
            top.set_ylabel(f"std ({unit})")
            top.set_title("lengths" if unit == "mm" else "angles", fontsize=9)
            top.legend(fontsize=7)
            bottom.errorbar(x, sub["bias"] * 1e3, yerr=2 * sub["bias_se"] * 1e3, fmt="o", ms=3,
                            capsize=2, label="bias ± 2 SE")
            bottom.axhline(0, color="k", lw=0.5)
            bottom.set_ylabel(f"bias ({unit})")
            bottom.legend(fontsize=7)
            for ax in (top, bottom):
                ax.set_xticks(x)
                ax.set_xlim(-0.6, len(sub) - 0.4)
            top.set_xticklabels([])
            bottom.set_xticklabels(sub["name"].tolist(), rotation=60, fontsize=8)
        fig.suptitle(f"Parameter errors, cell {cell['label']} ({cell['ok']} trials)", fontsize=10)
        fig.tight_layout()
        out.append((_save(fig, out_dir, f"parameters_{k}"),
                    f"Cell {cell['label']}: empirical against predicted standard deviation of each "
                    "parameter's error, and its bias with ±2 Monte-Carlo standard errors; lengths "
                    "in mm, angles in mrad." + note))
        names = params["name"].tolist()
        x = np.arange(len(names))
        corr = np.array([[np.nan if v is None else v for v in row] for row in cell["correlation"]],
                        dtype=float)
        fig, ax = plt.subplots(figsize=(7.5, 6.5))
        im = ax.imshow(corr, cmap="RdBu_r", vmin=-1, vmax=1)
        ax.set_xticks(x)
        ax.set_yticks(x)
        ax.set_xticklabels(names, rotation=90, fontsize=7)
        ax.set_yticklabels(names, fontsize=7)
        fig.colorbar(im, ax=ax, shrink=0.8, label="correlation (no unit)")
        ax.set_title(f"Empirical correlation of the parameter errors, {cell['label']}", fontsize=10)
        fig.tight_layout()
        out.append((_save(fig, out_dir, f"correlation_{k}"),
                    f"Cell {cell['label']}: correlation matrix of the parameter errors over the "
                    "trials." + note))
    return out


def histogram_figures(run, out_dir, limit=4):
    """Per cell: a histogram of each validation metric of the identified model over the trials,
    with the mean, the p95 and the p95's 95 % confidence interval from the tables."""
    data = run.trial_metrics()
    if data.empty:
        return []
    out = []
    shown = run.shown_cells(limit)
    note = run.left_out_note(shown)
    val = run.validation[run.validation["model"] == "identified"]
    for k, cell in enumerate(shown):
        rows = data[data["cell_id"] == cell["id"]]
        if rows.empty:
            continue
        fig, axes = plt.subplots(4, 3, figsize=(12, 10))
        for m, (metric, title) in enumerate(METRICS):
            unit = "mm" if metric.endswith("pos") else "mrad"
            for a, axis in enumerate(AXES):
                ax = axes[m, a]
                values = rows[_column(metric, axis)].to_numpy()
                ax.hist(values, bins=min(60, max(10, len(values) // 20)), color=f"C{a}", alpha=0.6)
                t = val[(val["cell_id"] == cell["id"]) & (val["metric"] == metric) &
                        (val["axis"] == axis)]
                if len(t):
                    t = t.iloc[0]
                    ax.axvline(t["mean"], color="k", lw=1, label="mean")
                    ax.axvline(t["p95"], color="C3", lw=1, label="p95")
                    if pd.notna(t["p95_ci_low"]) and pd.notna(t["p95_ci_high"]):
                        ax.axvspan(t["p95_ci_low"], t["p95_ci_high"], color="C3", alpha=0.2,
                                   label="p95 95 % CI")
                ax.set_xlabel(f"{title.split(' (')[0]}, {axis} ({unit})", fontsize=8)
                ax.set_ylabel("trials", fontsize=8)
                ax.yaxis.set_major_locator(MaxNLocator(integer=True))
                ax.tick_params(labelsize=7)
                if m == 0 and a == 0:
                    ax.legend(fontsize=7)
        fig.suptitle(f"Validation errors of the identified model, cell {cell['label']} "
                     f"({len(rows)} trials ok)", fontsize=10)
        fig.tight_layout()
        out.append((_save(fig, out_dir, f"histograms_{k}"),
                    f"Cell {cell['label']}: histograms of the validation metrics over the trials, "
                    "with the mean, the p95 and the p95's distribution-free 95 % confidence "
                    "interval (shaded) from validation.csv." + note))
    return out


def all_figures(run, out_dir):
    """Every figure, as (png path, caption) pairs."""
    # Figures over every cell first (the sensitivity indices, the sweeps), then the per-cell
    # figures of the chosen cells.
    figures = []
    figures += global_sensitivity_figure(run, out_dir)
    figures += sensitivity_figures(run, out_dir)
    figures += distribution_figure(run, out_dir)
    figures += realisation_figures(run, out_dir)
    figures += histogram_figures(run, out_dir)
    figures += parameter_figures(run, out_dir)
    return figures
