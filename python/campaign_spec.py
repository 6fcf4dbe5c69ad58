"""The campaign file (DESIGN.md, "Campaigns"): parsing, checks and the list of runs.

A campaign is a base config, a grid of ``--set`` values (``[grid]``: the product of its lists;
``[zip]``: lists of one length varied together, the zip then crossed with ``[grid]``), seeds,
the summary keys to collect, an output directory and an executor. Every run is one
``hardbody run BASE --out OUT/runs/NAME --set key=value ...`` whose NAME is a function of its
parameters, so the same campaign file always maps a grid point to the same directory.

Bad input raises CampaignError with one message naming the file and the key; the command line
turns it into exit status 2 before anything is written.
"""

from __future__ import annotations

import itertools
import json
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

TOP_KEYS = {"base", "out", "seeds", "collect", "grid", "zip", "set", "executor", "plot"}
EXECUTOR_KEYS = {
    "local": {"type", "jobs"},
    "slurm": {"type", "partition", "time", "memory", "max_parallel", "grace", "account",
              "sbatch_options", "srun"},
}


class CampaignError(Exception):
    """Bad campaign input: the message names the file and the key."""


def toml_value(v) -> str:
    """A Python value as the TOML text ``hardbody run --set key=VALUE`` parses back exactly."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"non-finite number {v}")
        return repr(v)  # shortest text that reads back to the same double
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise ValueError(f"unsupported value {v!r} (numbers, booleans, strings and lists of them)")


def _name_part(v) -> str:
    text = toml_value(v).replace(", ", "-").strip("[]\"")
    return re.sub(r"[^A-Za-z0-9._+-]", "-", text) or "empty"


@dataclass
class Run:
    """One run of the campaign: its grid values (key -> value), seed and directory name."""

    index: int
    params: dict
    seed: int | None
    name: str

    def sets(self) -> list[str]:
        out = [f"{k}={toml_value(v)}" for k, v in self.params.items()]
        if self.seed is not None:
            out.append(f"system.seed={self.seed}")
        return out


@dataclass
class Campaign:
    """A parsed campaign file. Paths are absolute (relative ones are taken from the file's folder)."""

    path: Path
    base: Path
    out: Path
    seeds: list
    collect: list
    grid: dict
    zipped: dict
    fixed: dict
    executor: dict
    plot_x: str | None
    runs: list = field(default_factory=list)

    @property
    def keys(self) -> list[str]:
        """The varied keys, in the order of the results columns."""
        return list(self.grid) + list(self.zipped)

    def run_dir(self, run: Run) -> Path:
        return self.out / "runs" / run.name

    def command(self, run: Run, hardbody: str = "hardbody", resume: bool = False) -> list[str]:
        """The ``hardbody run`` command of one run (also its reproducer)."""
        cmd = [hardbody, "run", str(self.base), "--out", str(self.run_dir(run)), "--quiet"]
        for k, v in self.fixed.items():
            cmd += ["--set", f"{k}={toml_value(v)}"]
        for s in run.sets():
            cmd += ["--set", s]
        if resume:
            cmd.append("--resume")
        return cmd


def _fail(path: Path, key: str, what: str):
    raise CampaignError(f"{path}: key '{key}': {what}")


def _check_values(path: Path, table: str, key: str, values) -> list:
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*\.[A-Za-z_][A-Za-z0-9_]*", key):
        _fail(path, f"{table}.{key}", "expected a config key 'section.key' (as in --set section.key=value)")
    if key == "system.seed":
        _fail(path, f"{table}.{key}", "seeds are given by the top-level 'seeds' list")
    if not isinstance(values, list) or not values:
        _fail(path, f"{table}.{key}", "expected a non-empty list of values")
    for v in values:
        try:
            toml_value(v)
        except ValueError as e:
            _fail(path, f"{table}.{key}", str(e))
    return values


def load(path) -> Campaign:
    """Reads and checks a campaign file; raises CampaignError naming the file and key."""
    path = Path(path).absolute()
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except FileNotFoundError:
        raise CampaignError(f"{path}: cannot open (no such file)") from None
    except IsADirectoryError:
        raise CampaignError(f"{path}: is a directory, not a campaign file") from None
    except tomllib.TOMLDecodeError as e:
        raise CampaignError(f"{path}: {e}") from None
    except OSError as e:
        raise CampaignError(f"{path}: cannot read: {e.strerror}") from None
    unknown = sorted(set(doc) - TOP_KEYS)
    if unknown:
        _fail(path, unknown[0], f"unknown key (expected one of {', '.join(sorted(TOP_KEYS))})")
    here = path.parent
    if not isinstance(doc.get("base"), str):
        _fail(path, "base", "required: the path of the base config (a string)")
    base = (here / doc["base"]).resolve()
    if not base.is_file():
        _fail(path, "base", f"{base}: no such file")
    out = doc.get("out", f"campaign-{path.stem}")
    if not isinstance(out, str) or not out:
        _fail(path, "out", "expected a directory path (a string)")
    seeds = doc.get("seeds", [None])
    if not isinstance(seeds, list) or not seeds or not all(
            s is None or (isinstance(s, int) and not isinstance(s, bool) and s >= 0) for s in seeds):
        _fail(path, "seeds", "expected a non-empty list of integers >= 0")
    if len(set(seeds)) != len(seeds):
        _fail(path, "seeds", "a seed is repeated")
    collect = doc.get("collect", ["Z"])
    if not isinstance(collect, list) or not collect or not all(isinstance(c, str) and c for c in collect):
        _fail(path, "collect", "expected a non-empty list of summary.json key names")
    tables = {}
    for t in ["grid", "zip", "set"]:
        v = doc.get(t, {})
        if not isinstance(v, dict):
            _fail(path, t, "expected a table of \"section.key\" = ...")
        tables[t] = v
    grid = {k: _check_values(path, "grid", k, v) for k, v in tables["grid"].items()}
    zipped = {k: _check_values(path, "zip", k, v) for k, v in tables["zip"].items()}
    lengths = {len(v) for v in zipped.values()}
    if len(lengths) > 1:
        _fail(path, "zip", f"the lists have different lengths ({', '.join(f'{k}: {len(v)}' for k, v in zipped.items())})")
    for k in zipped:
        if k in grid:
            _fail(path, f"zip.{k}", "is also in [grid]")
    fixed = {}
    for k, v in tables["set"].items():
        _check_values(path, "set", k, [v])
        if k in grid or k in zipped:
            _fail(path, f"set.{k}", "is also varied in [grid] or [zip]")
        fixed[k] = v
    executor = dict(doc.get("executor", {"type": "local"}))
    etype = executor.get("type", "local")
    if etype not in EXECUTOR_KEYS:
        _fail(path, "executor.type", f"'{etype}': expected \"local\" or \"slurm\"")
    executor["type"] = etype
    for k in executor:
        if k not in EXECUTOR_KEYS[etype]:
            _fail(path, f"executor.{k}", f"unknown key for executor type \"{etype}\" "
                  f"(expected one of {', '.join(sorted(EXECUTOR_KEYS[etype]))})")
    jobs = executor.get("jobs", 1)
    if not isinstance(jobs, int) or isinstance(jobs, bool) or jobs < 1:
        _fail(path, "executor.jobs", "expected an integer >= 1 (cores used at once)")
    plot = doc.get("plot", {})
    if not isinstance(plot, dict) or set(plot) - {"x"}:
        _fail(path, "plot", "expected a table with the key 'x' (the grid key on the x axis)")
    plot_x = plot.get("x")
    if plot_x is not None and plot_x not in grid and plot_x not in zipped:
        _fail(path, "plot.x", f"'{plot_x}' is not a key of [grid] or [zip]")
    c = Campaign(path=path, base=base, out=(here / out).absolute(), seeds=seeds, collect=collect,
                 grid=grid, zipped=zipped, fixed=fixed, executor=executor, plot_x=plot_x)
    c.runs = expand(c)
    return c


def expand(c: Campaign) -> list[Run]:
    """Every run: the product of [grid] (in file order) with the zip, then the seeds."""
    zip_rows = [dict(zip(c.zipped, vals)) for vals in zip(*c.zipped.values())] if c.zipped else [{}]
    points = []
    for vals in itertools.product(*c.grid.values()):
        for z in zip_rows:
            points.append({**dict(zip(c.grid, vals)), **z})
    short = [k.split(".", 1)[1] for k in c.keys]
    label = dict(zip(c.keys, short)) if len(set(short)) == len(short) else {k: k for k in c.keys}
    runs, names = [], {}
    for p in points:
        for s in c.seeds:
            parts = [f"{label[k]}={_name_part(v)}" for k, v in p.items()]
            if s is not None:
                parts.append(f"seed={s}")
            name = ",".join(parts) or "run"
            if name in names:
                raise CampaignError(f"{c.path}: runs {names[name]} and {len(runs)} get the same "
                                    f"directory name '{name}' (a value repeated in a list?)")
            names[name] = len(runs)
            runs.append(Run(index=len(runs), params=p, seed=s, name=name))
    return runs
