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
      trials    (read on first use; trials_of and iter_trials read a cell, or a chunk, at a
                time) one row per recorded trial, in the tables' units, each named in the column:
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
    Tables are pandas DataFrames, or numpy structured arrays without pandas. The cells, tables
    and summary are read at once; the trials only when asked for, so a run of any size opens in
    constant time and memory, and read cell by cell (trials_of, iter_trials) its memory is one
    chunk's.
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
        self._connections = {}
        self._columns = None  # the trial table's store columns, read once (_trial_columns)
        self._stores = [p for p in stores if os.path.isfile(p)]
        self._cells = self._read_cells()
        varied = varied_keys(self.manifest.get("study", {}))
        settings = 3 + _CELL_JSON.index("settings")
        self.cells = _records(
            ["cell_id", "ord", "label"] + list(_CELL_JSON) + ["design_sigma_min", "pool_report"] +
            varied,
            [c + tuple(_setting(c[settings] or {}, k) for k in varied) for c in self._cells],
            as_pandas)
        self._trials = None
        tables = os.path.join(path, "tables")
        self.tables = {os.path.splitext(os.path.basename(p))[0]: _read_csv(p, as_pandas)
                       for p in sorted(glob.glob(os.path.join(tables, "*.csv")))}
        summary = os.path.join(tables, "summary.json")
        self.summary = None
        if os.path.isfile(summary):
            with open(summary, encoding="utf-8") as f:
                self.summary = json.load(f)

    def _connect(self, store):
        """The store's read-only connection, opened once and kept: a connection per query would
        leave each one's page cache behind until it is collected (about 2 MB a chunk)."""
        if store not in self._connections:
            self._connections[store] = sqlite3.connect(f"file:{store}?mode=ro", uri=True)
        return self._connections[store]

    def close(self):
        """Closes the stores (also when the Run is collected)."""
        for db in getattr(self, "_connections", {}).values():
            db.close()
        self._connections = {}

    def __del__(self):
        self.close()

    def _read_cells(self):
        rows = {}
        for store in self._stores:
            db = self._connect(store)
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
        if self._columns is not None:
            return self._columns
        present = []
        if self._stores:  # no store yet: no trials, no metric columns
            db = self._connect(self._stores[0])
            present = [c[1] for c in db.execute("PRAGMA table_info(trials)")]
        metrics = [c for c in present if c.startswith("val_")] + \
                  [c for c in present if c.startswith("nom_")]
        missed = ["missed_configurations"] if "missed_configurations" in present else []
        coverage = [c for c in ("coverage", "coverage_total") if c in present]
        self._columns = _TRIAL_LEADING + metrics + ["seconds"] + missed + coverage
        return self._columns

    @property
    def trials(self):
        """Every recorded trial (read on first use, then kept): see the class's docstring. For a
        large run, trials_of(cell) or iter_trials() read a cell or a chunk at a time."""
        if self._trials is None:  # in study order; a trial of a cell no store lists comes last
            order = {c[0]: c[1] for c in self._cells}
            rows = sorted(self._rows_where("1", (), False),
                          key=lambda r: (order.get(r[0], 1 << 30), r[0], r[1]))
            self._trials = self._trial_table(rows)
        return self._trials

    def trials_of(self, cell, start=0, stop=None):
        """One cell's recorded trials with index start <= trial < stop (every one by default), in
        trial order, as the trials table's columns. `cell` is a cell_id or a label."""
        return self._trial_table(self._cell_rows(self._cell(cell)[0], start, stop, False))

    def iter_trials(self, cells=None, chunk_size=20000):
        """The recorded trials cell by cell (the given cells, ids or labels, else every cell in
        study order), each cell in chunks of at most chunk_size trials in trial order: a
        generator of tables with the trials table's columns. Memory stays about one chunk's,
        whatever the run's size."""
        if chunk_size < 1:
            raise ValueError(f"chunk_size: expected 1 or more trials, got {chunk_size}")
        ids = [c[0] for c in self._cells] if cells is None else [self._cell(c)[0] for c in cells]
        for cell_id in ids:
            last = self._last_trial(cell_id)
            for start in range(0, last + 1, chunk_size):
                rows = self._cell_rows(cell_id, start, start + chunk_size, False)
                if rows:
                    yield self._trial_table(rows)

    def _trial_table(self, rows):
        shown = [_display_column(c) for c in self._trial_columns()]
        if self._as_pandas:  # scaled in place: one copy of the rows fewer
            table = _pandas.DataFrame.from_records(rows, columns=[name for name, _ in shown])
            for name, factor in shown:
                if factor is not None:
                    table[name] = table[name] * factor
            return table
        return _records(
            [name for name, _ in shown],
            [tuple(v * f if f is not None and v is not None else v
                   for v, (_, f) in zip(r, shown)) for r in rows],
            self._as_pandas)

    def _cell(self, cell):
        match = [c for c in self._cells if cell in (c[0], c[2])]
        if not match:
            known = ", ".join(f"{c[2]} ({c[0]})" for c in self._cells)
            raise _error(self.path, f"no cell '{cell}'; the cells are: {known}")
        return match[0]

    def _rows_where(self, where, params, with_errors):
        """The trials of every store that satisfy `where`, the first store's record of a trial
        kept (as the tables merge them), in (cell_id, trial) order."""
        columns = ", ".join(self._trial_columns() + (["errors"] if with_errors else []))
        query = f"SELECT {columns} FROM trials WHERE {where} ORDER BY cell_id, trial"
        if len(self._stores) == 1:  # the usual run: nothing to merge
            return self._connect(self._stores[0]).execute(query, params).fetchall()
        rows = {}
        for store in self._stores:
            for r in self._connect(store).execute(query, params):
                rows.setdefault((r[0], r[1]), r)
        return [rows[k] for k in sorted(rows)]

    def _cell_rows(self, cell_id, start, stop, with_errors):
        if stop is None:
            return self._rows_where("cell_id = ? AND trial >= ?", (cell_id, start), with_errors)
        return self._rows_where("cell_id = ? AND trial >= ? AND trial < ?", (cell_id, start, stop),
                                with_errors)

    def _last_trial(self, cell_id):
        last = -1
        for store in self._stores:
            db = self._connect(store)
            (value,) = db.execute("SELECT MAX(trial) FROM trials WHERE cell_id = ?",
                                  (cell_id,)).fetchone()
            if value is not None:
                last = max(last, value)
        return last

    def _count_trials(self):
        if self._trials is not None:
            return len(self._trials)
        if len(self._stores) == 1:
            db = self._connect(self._stores[0])
            return db.execute("SELECT COUNT(*) FROM trials").fetchone()[0]
        keys = set()  # a trial recorded in two stores counts once
        for store in self._stores:
            db = self._connect(store)
            keys.update(db.execute("SELECT cell_id, trial FROM trials"))
        return len(keys)

    def errors(self, cell):
        """Parameter errors (estimate - truth, SI) of one cell's successful trials: a table with
        the column `trial` and one column per parameter (cells' parameter_names). `cell` is a
        cell_id or a label."""
        match = self._cell(cell)
        cell_id, names = match[0], match[4]
        rows = []
        for r in self._cell_rows(cell_id, 0, None, True):
            if r[-1] is None:
                continue
            values = np.frombuffer(r[-1], dtype="<f8")
            rows.append((r[1], *values.tolist()))
        return _records(["trial"] + list(names), rows, self._as_pandas)

    def __repr__(self):
        return (f"lrcal.Run('{self.path}', {len(self._cells)} cells, {self._count_trials()} trials, "
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
