"""Issue 13: a fuzz corpus for the pair queries. 500 JSON-lines queries mutated with a fixed seed
from valid examples (keys dropped or renamed, types swapped, huge/tiny/NaN-like numbers,
truncated lines, nested garbage) go through `hardbody distance` and `hardbody contact-time`:
every one exits 0 with a well-formed answer or 2 with one message naming the line; none crashes,
hangs (timeout) or exits otherwise."""
import copy
import json
import math
import os
import random
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor

HB = os.environ.get("HARDBODY", "hardbody")
SEED = 13
CASES = 500
TIMEOUT = 20  # seconds per case; the slowest valid query takes well under one


def body(shape, pos, q=(1, 0, 0, 0), v=(0, 0, 0), w=(0, 0, 0)):
    return {"shape": shape, "position": list(pos), "orientation": list(q),
            "velocity": list(v), "angular_velocity": list(w)}


SHAPES = [
    {"type": "sphere", "radius": 0.5},
    {"type": "ellipsoid", "semi_axes": [2.0, 1.0, 0.5]},
    {"type": "superquadric", "semi_axes": [1.0, 0.5, 0.5], "exponents": [4.0, 4.0, 8.0]},
    {"type": "ellipsoid", "semi_axes": [20.0, 0.1, 0.1]},
]
EXAMPLES = [
    {"a": body(SHAPES[0], (0, 0, 0), v=(1, 0, 0)), "b": body(SHAPES[0], (3, 0, 0), v=(-1, 0, 0)), "t_max": 10},
    {"a": body(SHAPES[1], (0, 0, 0), (0.9, 0.1, 0.3, 0.2), w=(0, 0, 2)),
     "b": body(SHAPES[2], (4, 0.5, 0), v=(-1, 0, 0.1)), "t_max": 5},
    {"a": body(SHAPES[1], (0, 0, 0)), "b": body(SHAPES[1], (1, 0.5, 0), (0.7, 0, 0, 0.7)), "t_max": 1},  # overlap
    {"a": body(SHAPES[3], (0, 0, 0), w=(0.5, 0, 0)), "b": body(SHAPES[3], (0, 0, 0.1), (0.7, 0, 0, 0.7)), "t_max": 2},
    {"a": body(SHAPES[2], (0, 0, 0), v=(0, 0.2, 0), w=(1, 1, 0)),
     "b": body(SHAPES[0], (0.5, 2, 0), w=(0, 3, 0)), "t_max": 3},
]
WEIRD_NUMBERS = [0, -0.0, 1e308, -1e308, 1e-308, 5e-324, 1e200, 1e-200, 1e20, -1e-20, 2 ** 63, -3]
WEIRD_TOKENS = ["1e400", "-1e400", "NaN", "Infinity", "-Infinity", "nan", "1e-400", "0x10", "01", ".5",
                "1.", "+1", "1e", "true", "null", "\"1\"", "[]", "{}"]
GARBAGE = [None, True, "sphere", "", [], {}, [1, 2], [[[[1]]]], {"x": {"y": [1, {"z": None}]}},
           [0.0] * 50, "\u00e9\u4e2d", {"type": "sphere"}]


def paths(obj, prefix=()):
    """Every path to a value in obj."""
    out = []
    if isinstance(obj, dict):
        for k, v in obj.items():
            out.append(prefix + (k,))
            out += paths(v, prefix + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            out.append(prefix + (i,))
            out += paths(v, prefix + (i,))
    return out


def parent(obj, path):
    for p in path[:-1]:
        obj = obj[p]
    return obj


def typo(rng, key):
    k = list(key)
    op = rng.randrange(4)
    i = rng.randrange(len(k))
    if op == 0:
        del k[i]
    elif op == 1:
        k.insert(i, rng.choice("abcxyz_"))
    elif op == 2 and len(k) > 1:
        j = min(i + 1, len(k) - 1)
        k[i], k[j] = k[j], k[i]
    else:
        k[i] = k[i].upper()
    return "".join(k) or "_"


def raw(tokens, text):
    """A placeholder for text written into the line as is (not valid JSON, or nested too deep
    for Python's json module)."""
    tokens.append(text)
    return f"\x00RAW{len(tokens) - 1}\x00"


def mutate(rng, example):
    """One mutated JSON line (text: some mutations are not valid JSON)."""
    q = copy.deepcopy(example)
    tokens = []
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        ps = paths(q)
        if not ps:
            break
        path = rng.choice(ps)
        par = parent(q, path)
        kind = rng.randrange(9)
        if kind == 0 and isinstance(par, dict):  # drop a key
            del par[path[-1]]
        elif kind == 1 and isinstance(par, dict):  # rename a key
            par[typo(rng, str(path[-1]))] = par.pop(path[-1])
        elif kind == 2:  # swap the type
            par[path[-1]] = rng.choice(GARBAGE)
        elif kind == 3:  # extreme but valid number
            par[path[-1]] = rng.choice(WEIRD_NUMBERS)
        elif kind == 4:  # a token that is not a finite double (written into the text below)
            par[path[-1]] = raw(tokens, rng.choice(WEIRD_TOKENS))
        elif kind == 5 and isinstance(par[path[-1]], list):  # wrong length
            lst = par[path[-1]]
            if lst and rng.random() < 0.5:
                lst.pop()
            else:
                lst.append(rng.choice(WEIRD_NUMBERS))
        elif kind == 6:  # nested garbage
            depth = rng.choice([3, 30, 300, 3000])
            par[path[-1]] = raw(tokens, "[" * depth + "1" + "]" * depth)
        elif kind == 7 and isinstance(par, dict):  # an extra key
            par[typo(rng, "extra")] = rng.choice(GARBAGE + WEIRD_NUMBERS)
        else:  # scale a number by a huge or tiny factor
            v = par[path[-1]]
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                par[path[-1]] = v * rng.choice([1e300, 1e-300, 1e150, -1e10, 0.0])
    text = json.dumps(q)
    for i, t in enumerate(tokens):
        text = text.replace(json.dumps(f"\x00RAW{i}\x00"), t)
    if rng.random() < 0.08:  # truncated line
        text = text[: rng.randrange(len(text))]
    if rng.random() < 0.03:  # not an object at all
        text = rng.choice(["[]", "1", "\"a\"", "null", "{}", "{\"a\": 1}"])
    return text


def corpus():
    rng = random.Random(SEED)
    return [(rng.choice(["distance", "contact-time"]), mutate(rng, rng.choice(EXAMPLES)))
            for _ in range(CASES)]


def run_case(case):
    cmd, text = case
    t0 = time.monotonic()
    try:
        r = subprocess.run([HB, cmd], input=text + "\n", capture_output=True, text=True,
                           timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return case, None, "", f"timeout after {TIMEOUT} s", 0.0
    return case, r.returncode, r.stdout, r.stderr, time.monotonic() - t0


def finite_triple(x):
    return isinstance(x, list) and len(x) == 3 and all(isinstance(v, float) and math.isfinite(v) for v in x)


def check(case, code, out, err):
    """'' if the outcome keeps the contract, else what is wrong."""
    cmd, text = case
    if code == 2:
        lines = err.strip().splitlines()
        if out:
            return "exit 2 with output"
        if len(lines) != 1 or not lines[0].startswith("hardbody: error: "):
            return f"exit 2 without one error line: {err!r}"
        if "<stdin>:1:" not in lines[0] and "--eps-d" not in lines[0]:
            return f"message does not name the line: {err!r}"
        if "json.exception" in lines[0] or len(lines[0]) > 600:
            return f"raw or overlong message: {err!r}"
        return ""
    if code != 0:
        return f"exit {code}: {err!r}"
    outs = out.strip().splitlines()
    if len(outs) != 1:
        return f"exit 0 with {len(outs)} output lines"
    o = json.loads(outs[0])
    if cmd == "distance":
        if not (isinstance(o.get("distance"), float) and math.isfinite(o["distance"])
                and finite_triple(o.get("point_a")) and finite_triple(o.get("point_b"))):
            return f"bad distance answer {o}"
    else:
        t = o.get("time")
        if t is None:
            if o.get("point") is not None or o.get("normal") is not None:
                return f"bad contact answer {o}"
        elif not (isinstance(t, float) and t >= 0.0 and finite_triple(o.get("point"))
                  and finite_triple(o.get("normal"))):
            return f"bad contact answer {o}"
    if err and not err.startswith("hardbody: warning: "):
        return f"exit 0 with stderr {err!r}"
    return ""


def test_fuzzed_pair_queries_exit_0_or_2_with_a_message():
    cases = corpus()
    assert len(cases) == CASES and len(set(cases)) > 0.9 * CASES
    t0 = time.monotonic()
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(run_case, cases))
    wall = time.monotonic() - t0
    problems = []
    counts = {0: 0, 2: 0}
    for case, code, out, err, _ in results:
        what = check(case, code, out, err)
        if what:
            problems.append(f"{case[0]} {case[1][:300]!r}: {what}")
        elif code in counts:
            counts[code] += 1
    slowest = max(r[4] for r in results)
    print(f"\n  {CASES} fuzzed queries in {wall:.1f} s (slowest {slowest:.2f} s): "
          f"{counts[0]} answered, {counts[2]} refused with exit 2, {len(problems)} problems")
    assert not problems, "\n".join(problems[:20])
    assert counts[0] > 20 and counts[2] > 200  # the corpus exercises both outcomes
