"""`hardbody run` refuses bad [box], [walls] and [thermostat] keys (DESIGN.md "Boxes and walls",
"Thermostat"), in the file or by --set: exit 2, one message line naming the key, nothing written
into --out (the directory is not even created)."""
import math
import os

import pytest

import test_cli
# refused(tmp_path, args, text): `hardbody run c.toml --out o ARGS`, exit 2, one line, no o/; the line.
# SPHERES: 108 spheres of radius 0.5 at phi = 0.3, 13 lines.
from test_config_errors import SPHERES, refused

# A relative HARDBODY (build-config/apps/hardbody/hardbody) is taken from where pytest starts:
# each run's cwd is its own tmp_path.
if os.sep in test_cli.HB:
    test_cli.HB = os.path.abspath(test_cli.HB)

N, V_BODY, PHI = 108, math.pi / 6, 0.3
NO_PHI = SPHERES.replace("packing_fraction = 0.3\n", "")  # 12 lines
R_PHI = (N * V_BODY / PHI * 3 / (4 * math.pi)) ** (1 / 3)  # the container of N bodies at PHI: 3.557
LZ_THIN = 0.1 * (N * V_BODY / PHI / 0.1) ** (1 / 3)  # Lz of aspect [1, 1, 0.1]: 1.235 < 2 body lengths

BAD = [
    # (id, config text, expected parts of the message)
    ("aspect-zero", SPHERES + "[box]\naspect = [1, 1, 0]\n", ["c.toml:15: key 'box.aspect'", "positive"]),
    ("aspect-nan", SPHERES + "[box]\naspect = [1, nan, 1]\n", ["key 'box.aspect'", "finite"]),
    ("aspect-two", SPHERES + "[box]\naspect = [1, 2]\n", ["key 'box.aspect'"]),
    ("aspect-thin", SPHERES + "[box]\naspect = [1, 1, 100]\n", ["key 'box.aspect'", "two body lengths"]),
    ("planes-string", SPHERES + "[walls]\nplanes = \"z\"\n", ["c.toml:15: key 'walls.planes'"]),
    ("planes-axis", SPHERES + "[walls]\nplanes = [\"w\"]\n", ["key 'walls.planes'", "\"w\""]),
    ("planes-twice", SPHERES + "[walls]\nplanes = [\"x\", \"x\"]\n", ["key 'walls.planes'", "twice"]),
    ("planes-short-side", SPHERES + "[box]\naspect = [1, 1, 0.1]\n[walls]\nplanes = [\"z\"]\n",
     ["key 'walls.planes'", "along z", f"{LZ_THIN:.6g}", "two body lengths (2"]),
    ("sphere-negative", NO_PHI + "[walls]\nsphere = -3.0\n", ["c.toml:14: key 'walls.sphere'", "positive"]),
    ("sphere-and-planes", NO_PHI + "[walls]\nplanes = [\"z\"]\nsphere = 6.0\n",
     ["key 'walls.sphere'", "walls.planes and walls.sphere exclude each other"]),
    ("sphere-and-aspect", NO_PHI + "[box]\naspect = [2, 1, 1]\n[walls]\nsphere = 6.0\n", ["key 'box.aspect'"]),
    ("sphere-too-small", SPHERES + f"[walls]\nsphere = {0.9 * R_PHI}\n",
     ["key 'walls.sphere'", f"the container is too small for {N} bodies at phi = 0.3: it needs radius {R_PHI:.10g}"]),
    ("sphere-too-large", SPHERES + f"[walls]\nsphere = {1.2 * R_PHI}\n",
     ["key 'walls.sphere'", f"the container is larger than {N} bodies at phi = 0.3 need (radius {R_PHI:.10g}",
      f"omit system.packing_fraction or set walls.sphere = {R_PHI:.10g}"]),
    ("sphere-two-lengths", NO_PHI.replace("particles = 108", "particles = 2") + "[walls]\nsphere = 1.9\n",
     ["key 'walls.sphere'", "below two body lengths"]),
    ("sphere-too-dense", NO_PHI + "[walls]\nsphere = 2.5\n", ["key 'walls.sphere'", "is not below"]),
    ("thermostat-type", SPHERES + "[thermostat]\ntype = \"berendsen\"\n", ["c.toml:15: key 'thermostat.type'"]),
    ("rate-negative-none", SPHERES + "[thermostat]\nrate = -1.0\n", ["key 'thermostat.rate'", "negative"]),
    ("rate-negative-andersen", SPHERES + "[thermostat]\ntype = \"andersen\"\nrate = -1.0\n",
     ["key 'thermostat.rate'", "negative"]),
    ("rate-missing-andersen", SPHERES + "[thermostat]\ntype = \"andersen\"\n", ["key 'thermostat.rate'", "positive"]),
    ("rate-inf", SPHERES + "[thermostat]\ntype = \"andersen\"\nrate = inf\n", ["key 'thermostat.rate'", "finite"]),
    ("during", SPHERES + "[thermostat]\nduring = \"sometimes\"\n", ["key 'thermostat.during'"]),
    ("unknown-key", SPHERES + "[walls]\nplane = [\"z\"]\n", ["unknown key 'walls.plane' (did you mean 'walls.planes'?)"]),
]


@pytest.mark.parametrize("text,expect", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_boundaries_and_thermostat_are_refused(tmp_path, text, expect):
    line = refused(tmp_path, [], text)
    assert line.startswith("hardbody: error: "), line
    for part in expect:
        assert part in line, (part, line)


@pytest.mark.parametrize("option,expect", [
    ('walls.planes=["z","q"]', "key 'walls.planes'"),
    ("walls.sphere=0", "key 'walls.sphere'"),
    ("walls.sphere=3", "key 'walls.sphere': the container is too small"),
    ("box.aspect=[1,1,-2]", "key 'box.aspect'"),
    ("thermostat.rate=-0.5", "key 'thermostat.rate'"),
    ("thermostat.type=nose-hoover", "key 'thermostat.type'"),
    ("thermostat.during=later", "key 'thermostat.during'"),
])
def test_set_errors_name_the_option_and_the_key(tmp_path, option, expect):
    line = refused(tmp_path, ["--set", option])
    assert line.startswith(f"hardbody: error: --set {option}: {expect}"), line


def test_set_values_combine_with_the_file(tmp_path):
    # the file's planes and a --set container exclude each other; named at the option
    line = refused(tmp_path, ["--set", "walls.sphere=6"], NO_PHI + "[walls]\nplanes = [\"z\"]\n")
    assert "--set walls.sphere=6: key 'walls.sphere': walls.planes and walls.sphere exclude each other" in line
    # a --set list reaches the geometric check
    line = refused(tmp_path, ["--set", 'walls.planes=["z"]'], SPHERES + "[box]\naspect = [1, 1, 0.1]\n")
    assert "key 'walls.planes'" in line and "along z" in line, line
