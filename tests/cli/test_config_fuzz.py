"""Config fuzz corpus (issue 13): 300 configs mutated with a fixed seed from examples/*.toml
(keys deleted, duplicated and renamed, wrong types, extreme numbers, empty strings, unknown
sections, broken TOML syntax, unicode), each run by `hardbody run` with a timeout. Every case must
exit 0 or 2; exit 2 with one message line naming the problem (the file, or the --set option) and
nothing left behind; none may crash (exit 3 from an exception, a signal, a sanitizer report) or
hang. The bases are the examples made small (few bodies, short runs), so the corpus runs in about
a minute in Release."""
import math
import os
import random
import shutil
import subprocess
import tomllib
from pathlib import Path

import pytest

HB = os.environ.get("HARDBODY", "hardbody")
EXAMPLES = Path(os.environ.get("HARDBODY_EXAMPLES", Path(__file__).resolve().parents[2] / "examples"))
CASES = 300
SEED = 13
TIMEOUT = 30  # seconds per case; the cases take well under a second in Release

# the examples made small: few bodies, short runs (a mutation may still change these keys)
SMALL = {
    "system": {"particles": 108},
    "run": {"equilibrate_time": 0.02, "time": 0.05},
    "output": {"log_interval": 0.025, "snapshot_interval": 0.025},
    "observables": {"interval": 0.01, "max_lag": 0.05, "gr_interval": 0.025},
}
SPECIES_COUNT = 40
MANY_BODIES = {"ellipsoids", "superquadrics"}  # grown from a lattice: 64 bodies are enough


def base_configs():
    out = {}
    for path in sorted(EXAMPLES.glob("*.toml")):
        cfg = tomllib.loads(path.read_text())
        for sec, keys in SMALL.items():
            if sec == "system" and "particles" not in cfg.get("system", {}):
                continue
            cfg.setdefault(sec, {}).update(keys)
        if path.stem in MANY_BODIES:
            cfg["system"]["particles"] = 64
        for sp in cfg.get("species", []):
            sp["count"] = SPECIES_COUNT
        out[path.stem] = cfg
    return out


# ---- a small TOML writer (values of any type: mutations put tables where numbers belong) ----

def value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{key(k)} = {value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v))


def key(k):
    if k and all(c.isascii() and (c.isalnum() or c in "_-") for c in k):
        return k
    return value(k)


def dumps(cfg):
    lines = []
    for sec, body in cfg.items():
        if isinstance(body, list) and all(isinstance(x, dict) for x in body) and body:
            for entry in body:
                lines.append(f"[[{key(sec)}]]")
                lines += [f"{key(k)} = {value(v)}" for k, v in entry.items()]
        elif isinstance(body, dict):
            lines.append(f"[{key(sec)}]")
            lines += [f"{key(k)} = {value(v)}" for k, v in body.items()]
        else:
            lines.insert(0, f"{key(sec)} = {value(body)}")
    return "\n".join(lines) + "\n"


# ---- mutations -------------------------------------------------------------------------------

EXTREME = [0, -1, 0.0, -0.0, 1e308, -1e308, 1e-308, 5e-324, float("nan"), float("inf"),
           float("-inf"), 2**63 - 1, -(2**63), 10**6, 1e9, 1e-9, 0.5]
WRONG = ["", "abc", True, [1.0, 2.0], [1.0, 2.0, 3.0], {"a": 1}, [], "0.5", "∞"]
UNICODE = ["é", "∞", "\u202e", "\u200b", "🙂", "日本", "\ufeff"]


def places(cfg):
    """(container, key) of every scalar or array value, tables of [[species]] included."""
    out = []

    def walk(d):
        for k, v in d.items():
            if isinstance(v, dict):
                walk(v)
            elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
                for x in v:
                    walk(x)
            else:
                out.append((d, k))
                if isinstance(v, list):
                    out.extend((v, i) for i in range(len(v)))

    walk(cfg)
    return out


def tables(cfg):
    out = []

    def walk(d):
        out.append(d)
        for v in d.values():
            if isinstance(v, dict):
                walk(v)
            elif isinstance(v, list):
                for x in v:
                    if isinstance(x, dict):
                        walk(x)

    walk(cfg)
    return out


def typo(rng, word):
    if not word:
        return "x"
    i = rng.randrange(len(word))
    return rng.choice([word[:i] + word[i + 1:], word[:i] + "x" + word[i:], word.upper(),
                       word[:i] + rng.choice(UNICODE) + word[i:], word + "s"]) or "y"


def mutate_tree(rng, cfg):
    kind = rng.choice(["delete", "delete_section", "rename", "rename_section", "wrong_type",
                       "extreme", "extreme", "extreme", "empty_string", "unknown_section",
                       "unknown_key", "unicode_value"])
    if not cfg or not places(cfg):
        kind = "unknown_section"
    if kind == "delete_section":
        del cfg[rng.choice(list(cfg))]
    elif kind in ("delete", "rename", "unknown_key"):
        t = rng.choice([t for t in tables(cfg) if t] or [cfg])
        k = rng.choice(list(t))
        if kind == "delete":
            del t[k]
        elif kind == "rename":
            t[typo(rng, k)] = t.pop(k)
        else:
            t[typo(rng, k) + "_extra"] = rng.choice(EXTREME)
    elif kind == "rename_section":
        k = rng.choice(list(cfg))
        cfg[typo(rng, k)] = cfg.pop(k)
    elif kind == "unknown_section":
        cfg[rng.choice(["extra", "systems", "Run", "шум"])] = {"x": 1}
    else:
        cont, k = rng.choice(places(cfg))
        cont[k] = {"wrong_type": rng.choice(WRONG), "extreme": rng.choice(EXTREME), "empty_string": "",
                   "unicode_value": rng.choice(UNICODE) * rng.randint(1, 3)}[kind]
    return kind


def mutate_text(rng, text):
    kind = rng.choice(["duplicate_line", "drop_char", "insert_char", "truncate", "unicode_text",
                       "bom", "bad_utf8"])
    lines = text.splitlines(keepends=True)
    if len(text) < 2:
        return "bom", b"\xef\xbb\xbf" + text.encode()
    if kind == "duplicate_line":
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
        return kind, "".join(lines).encode()
    if kind == "drop_char":
        i = rng.randrange(len(text))
        return kind, (text[:i] + text[i + 1:]).encode()
    if kind == "insert_char":
        i = rng.randrange(len(text))
        return kind, (text[:i] + rng.choice("=[]{}\"'#.,\n\\") + text[i:]).encode()
    if kind == "truncate":
        return kind, text[: rng.randrange(len(text))].encode()
    if kind == "unicode_text":
        i = rng.randrange(len(text))
        return kind, (text[:i] + rng.choice(UNICODE) + text[i:]).encode()
    if kind == "bom":
        return kind, b"\xef\xbb\xbf" + text.encode()
    i = rng.randrange(len(text))
    return kind, text[:i].encode() + b"\xff\xfe" + text[i:].encode()


def corpus():
    rng = random.Random(SEED)
    bases = base_configs()
    cases = []
    for n in range(CASES):
        name = rng.choice(sorted(bases))
        cfg = tomllib.loads(dumps(bases[name]))  # a deep copy
        kinds = [mutate_tree(rng, cfg) for _ in range(rng.choice([1, 1, 1, 2, 3]))]
        text = dumps(cfg)
        data = text.encode()
        if rng.random() < 0.25:
            kind, data = mutate_text(rng, text)
            kinds.append(kind)
        cases.append((f"{n:03d}@{name}@{'+'.join(kinds)}", data))
    return cases


def run_case(tmp_path, name, data):
    cfg = tmp_path / f"{name}.toml"
    cfg.write_bytes(data)
    out = tmp_path / f"out-{name}"
    try:
        r = subprocess.run([HB, "run", str(cfg), "--out", str(out), "--quiet"], cwd=tmp_path,
                           capture_output=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return "hangs (timeout)"
    err = r.stderr.decode(errors="replace")
    problem = None
    if r.returncode not in (0, 2):
        problem = f"exit {r.returncode}"
    elif any(w in err for w in ("Sanitizer", "runtime error", "Assertion")):
        problem = "sanitizer or assertion report"
    elif r.returncode == 2:
        lines = [l for l in err.splitlines() if l.strip()]
        if len(lines) != 1:
            problem = f"{len(lines)} message lines"
        elif cfg.name not in lines[0] and "--set" not in lines[0]:
            problem = "the message names neither the file nor an option"
        elif out.exists():
            problem = "files left behind"
    shutil.rmtree(out, ignore_errors=True)
    cfg.unlink()
    return problem and f"{problem}: {err.strip()[:300]}"


@pytest.mark.parametrize("chunk", range(6))
def test_config_fuzz_corpus(tmp_path, chunk):
    """50 cases per chunk (pytest can report them side by side): exit 0 or 2, one line, no hang."""
    failures = []
    cases = corpus()
    for name, data in cases[chunk::6]:
        problem = run_case(tmp_path, name, data)
        if problem:
            failures.append(f"{name}: {problem}")
    assert not failures, "\n".join(failures)


def test_corpus_is_fixed_and_varied():
    cases = corpus()
    assert len(cases) == CASES and corpus() == cases
    kinds = {k for name, _ in cases for k in name.split("@")[2].split("+")}
    assert {"extreme", "wrong_type", "delete", "rename", "unknown_section", "truncate"} <= kinds
    assert len({name.split("@")[1] for name, _ in cases}) == len(base_configs()) >= 4
