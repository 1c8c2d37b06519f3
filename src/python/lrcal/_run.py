"""lrcal.load_run: a run directory's trials and tables as pandas DataFrames (or numpy arrays).

A run directory (docs/FILE_FORMATS.md) holds manifest.json, trials.sqlite (and, after an
interrupted MPI job, trials.rank<r>.sqlite) and, once every trial is done, tables/*.csv and
tables/summary.json. The stores are opened read-only, so a run in progress can be read.
"""
import csv
import glob
import json
import os
import sqlite3

import numpy as np

try:
    import pandas as _pandas
except ImportError:  # pandas is optional: numpy structured arrays without it
    _pandas = None

# The trial table's leading columns; the validation metrics' columns (val_rms_pos_x ...,
# nom_...) are read from the run's own store, which names them (lrcal's one list of metric names:
# lrcal/kinematics/validation_metric.h).
_TRIAL_LEADING = ["cell_id", "trial", "status", "iterations", "residual_rms", "sigma_hat",
                  "sigma_min"]
_CELL_JSON = ("settings", "parameter_names", "predicted_std", "fixed_for_rank", "truth_errors",
              "predicted_std_truth")


def _display_column(name):
    """The trial table's name for a store column, with the tables' unit (mm, mrad) appended to
    every length and angle, and the factor from the store's SI value."""
    if name in ("residual_rms", "sigma_hat") or (name.startswith(("val_", "nom_")) and
                                                  "_pos_" in name):
        return name + "_mm", 1e3
    if name.startswith(("val_", "nom_")) and "_ori_" in name:
        return name + "_mrad", 1e3
    if name in ("coverage", "coverage_total"):
        return name + "_pct", 100.0
    return name, None


def _error(path, what):
    from . import InputError  # the module's, or the pure-Python stand-in without it
    error = InputError(f"{path}: {what}")
    error.where = path
    return error


def _records(columns, rows, as_pandas):
    """A table as a DataFrame, or as a numpy structured array (numbers float64/int64, text
    object) when pandas is not used."""
    if as_pandas:
        return _pandas.DataFrame.from_records(rows, columns=columns)
    dtypes = []
    for k, name in enumerate(columns):
        values = [r[k] for r in rows]
        if values and all(isinstance(v, bool) for v in values):
            dtypes.append((name, np.bool_))
        elif values and all(isinstance(v, int) and not isinstance(v, bool) for v in values):
            dtypes.append((name, np.int64))
        elif values and all(isinstance(v, (int, float)) or v is None for v in values):
            dtypes.append((name, np.float64))
        else:
            dtypes.append((name, object))
    fixed = [tuple(np.nan if (v is None and dt == np.float64) else v
                   for v, (_, dt) in zip(r, dtypes)) for r in rows]
    return np.array(fixed, dtype=dtypes)


def _read_csv(path, as_pandas):
    if as_pandas:
        return _pandas.read_csv(path)
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader)
        rows = list(reader)
    converted = []
    for k in range(len(header)):
        column = [r[k] for r in rows]
        for kind in (int, float):
            try:
                converted.append([kind(v) for v in column])
                break
            except ValueError:
                continue
        else:
            converted.append(column)
    return _records(header, list(zip(*converted)) if rows else [], False)


def _leaf_keys(value, prefix, keys):
    """Every leaf under `value` as a dotted key below `prefix` ("selection.count"), once each."""
    if isinstance(value, dict) and value:
        for k, v in value.items():
            _leaf_keys(v, k if prefix in ("", ".") else f"{prefix}.{k}", keys)
    elif prefix not in keys:
        keys.append(prefix)


def varied_keys(study):
    """The settings a study varies, as dotted keys (the columns cells.csv adds): every leaf of
    every sweep axis' values and every sensitivity input."""
    keys = []
    for axis in (study.get("sweep") or {}).get("axes", []):
        for v in axis.get("values", []):
            _leaf_keys(v, axis["key"], keys)
    for item in (study.get("sensitivity") or {}).get("inputs", []):
        _leaf_keys(None, item["key"], keys)
    return keys


def _setting(settings, key):
    value = settings
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            return None
        value = value[part]
    return value


class Run:
    """A run directory read back (lrcal.load_run).

    Attributes:
      path      the run directory
      manifest  manifest.json as a dict (study, seed, build, sessions)
      cells     one row per cell: cell_id, ord, label, settings (dict), parameter_names (list),
                predicted_std (list, SI), design_sigma_min, fixed_for_rank, pool_report,
                truth_errors (list, SI), then one column per setting the study varies, named by
                its key ("selection.count", "noise.sigma_mm": varied_keys), as in cells.csv
      trials    one row per recorded trial, in the tables' units, each named in the column:
                cell_id, trial, status, iterations, residual_rms_mm, sigma_hat_mm, sigma_min
                (σ_min of the design's G, SI), val_{rms,max}_pos_{x,y,z}_mm and
                val_{rms,max}_ori_{x,y,z}_mrad (validation errors of the identified model),
                nom_..._mm and nom_..._mrad (of the nominal model), seconds,
                missed_configurations (design configurations whose true beam missed its plane:
                no reading, left out of the fit), and with validation.coverage coverage_pct and
                coverage_total_pct (% of the validation poses within the stated 95 % radius,
                the data part and the total; NaN where a trial has none)
      tables    {name: table} for every tables/<name>.csv (units as the CSV headers say;
                empty until the run is complete)
      summary   tables/summary.json as a dict, or None
    Tables are pandas DataFrames, or numpy structured arrays without pandas.
    """

    def __init__(self, path, as_pandas, stores=None):
        """`stores`: the trial stores to read instead of the run's own (lrcal.report reads the
        consistent snapshot that `lrcal report` made of them)."""
        self.path = path
        self._as_pandas = as_pandas
        manifest = os.path.join(path, "manifest.json")
        if not os.path.isfile(manifest):
            raise _error(path, "not a run directory (no manifest.json); expected the --out "
                               "folder of lrcal run or lrcal.run_study")
        with open(manifest, encoding="utf-8") as f:
            self.manifest = json.load(f)
        if stores is None:
            stores = [os.path.join(path, "trials.sqlite")] + \
                sorted(glob.glob(os.path.join(path, "trials.rank*.sqlite")))
        self._stores = [p for p in stores if os.path.isfile(p)]
        self._cells = self._read_cells()
        varied = varied_keys(self.manifest.get("study", {}))
        settings = 3 + _CELL_JSON.index("settings")
        self.cells = _records(
            ["cell_id", "ord", "label"] + list(_CELL_JSON) + ["design_sigma_min", "pool_report"] +
            varied,
            [c + tuple(_setting(c[settings] or {}, k) for k in varied) for c in self._cells],
            as_pandas)
        stored = self._trial_columns()
        shown = [_display_column(c) for c in stored]
        self.trials = _records(
            [name for name, _ in shown],
            [tuple(v * f if f is not None and v is not None else v
                   for v, (_, f) in zip(r, shown)) for r in self._read_trials()],
            as_pandas)
        tables = os.path.join(path, "tables")
        self.tables = {os.path.splitext(os.path.basename(p))[0]: _read_csv(p, as_pandas)
                       for p in sorted(glob.glob(os.path.join(tables, "*.csv")))}
        summary = os.path.join(tables, "summary.json")
        self.summary = None
        if os.path.isfile(summary):
            with open(summary, encoding="utf-8") as f:
                self.summary = json.load(f)

    def _connect(self, store):
        return sqlite3.connect(f"file:{store}?mode=ro", uri=True)

    def _read_cells(self):
        rows = {}
        for store in self._stores:
            with self._connect(store) as db:
                present = {c[1] for c in db.execute("PRAGMA table_info(cells)")}
                # Columns a store written by an older lrcal lacks are read as NULL.
                json_columns = [c if c in present else f"NULL AS {c}" for c in _CELL_JSON]
                for r in db.execute(
                        f"SELECT cell_id, ord, label, {', '.join(json_columns)}, "
                        "design_sigma_min, pool_report FROM cells ORDER BY ord"):
                    n = len(_CELL_JSON)
                    decoded = [json.loads(v) if v else None for v in r[3:3 + n]]
                    rows.setdefault(r[0], (r[0], r[1], r[2], *decoded, r[3 + n], r[4 + n]))
        return sorted(rows.values(), key=lambda r: r[1])

    def _trial_columns(self):
        """The trial table's columns as the run's store names them: the leading ones, the
        validation metrics of the identified (val_*) and nominal (nom_*) models, seconds, and
        missed_configurations where the store records it (stores written before lrcal kept a trial
        whose beam missed at some configurations do not)."""
        present = []
        if self._stores:  # no store yet: no trials, no metric columns
            with self._connect(self._stores[0]) as db:
                present = [c[1] for c in db.execute("PRAGMA table_info(trials)")]
        metrics = [c for c in present if c.startswith("val_")] + \
                  [c for c in present if c.startswith("nom_")]
        missed = ["missed_configurations"] if "missed_configurations" in present else []
        coverage = [c for c in ("coverage", "coverage_total") if c in present]
        return _TRIAL_LEADING + metrics + ["seconds"] + missed + coverage

    def _read_trials(self, with_errors=False):
        rows = {}
        columns = ", ".join(self._trial_columns() + (["errors"] if with_errors else []))
        for store in self._stores:
            with self._connect(store) as db:
                for r in db.execute(f"SELECT {columns} FROM trials"):
                    rows.setdefault((r[0], r[1]), r)
        order = {c[0]: c[1] for c in self._cells}
        return sorted(rows.values(), key=lambda r: (order.get(r[0], 1 << 30), r[0], r[1]))

    def errors(self, cell):
        """Parameter errors (estimate - truth, SI) of one cell's successful trials: a table with
        the column `trial` and one column per parameter (cells' parameter_names). `cell` is a
        cell_id or a label."""
        match = [c for c in self._cells if cell in (c[0], c[2])]
        if not match:
            known = ", ".join(f"{c[2]} ({c[0]})" for c in self._cells)
            raise _error(self.path, f"no cell '{cell}'; the cells are: {known}")
        cell_id, names = match[0][0], match[0][4]
        rows = []
        for r in self._read_trials(with_errors=True):
            if r[0] != cell_id or r[-1] is None:
                continue
            values = np.frombuffer(r[-1], dtype="<f8")
            rows.append((r[1], *values.tolist()))
        return _records(["trial"] + list(names), rows, self._as_pandas)

    def __repr__(self):
        return (f"lrcal.Run('{self.path}', {len(self._cells)} cells, {len(self.trials)} trials, "
                f"tables: {', '.join(self.tables) or 'none yet'})")


def load_run(path, as_pandas=None):
    """Reads a run directory (lrcal run --out DIR, or lrcal.run_study): its manifest, cells,
    trials, every table of tables/ and summary.json; see lrcal.Run.

    as_pandas: True for pandas DataFrames, False for numpy structured arrays, None (default) for
    DataFrames if pandas is installed. Raises lrcal.InputError if `path` is not a run directory.
    """
    if as_pandas is None:
        as_pandas = _pandas is not None
    if as_pandas and _pandas is None:
        raise ImportError("load_run(as_pandas=True) needs pandas (Debian: python3-pandas)")
    return Run(os.fspath(path), as_pandas)
