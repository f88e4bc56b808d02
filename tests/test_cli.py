"""The command line: ``python -m ngfracture verify lshape ...``."""
import json
import os
import subprocess
import sys

import pytest

from ngfracture.cli import main
from ngfracture.output.atomic import write_json


def test_verify_writes_schema(tmp_path, capsys):
    out = tmp_path / "out.json"
    assert main(["verify", "lshape", "--order", "1", "--levels", "3", "--json", str(out)]) == 0
    res = json.loads(out.read_text())
    assert res["problem"] == "lshape" and res["variant"] == "dirichlet"
    assert res["order"] == 1 and res["model"] == "linear"
    assert [r["level"] for r in res["levels"]] == [0, 1, 2]
    for r in res["levels"]:
        assert set(r) == {"level", "ndof", "nverts", "h", "rel_l2", "rel_energy", "time_s"}
    # Rates over three levels of P1 with the corner singularity: energy near alpha = 0.544.
    assert abs(res["rates"]["energy"] - 0.5445) < 0.1
    assert res["rates"]["l2"] > 1.0
    assert "rates over the finest three levels" in capsys.readouterr().out
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]  # no temp file left


def test_existing_json_needs_force(tmp_path):
    out = tmp_path / "out.json"
    out.write_text("keep me")
    with pytest.raises(SystemExit) as exc:
        main(["verify", "lshape", "--levels", "2", "--json", str(out)])
    assert exc.value.code == 2
    assert out.read_text() == "keep me"
    assert main(["verify", "lshape", "--levels", "2", "--json", str(out), "--force"]) == 0
    assert json.loads(out.read_text())["problem"] == "lshape"
    with pytest.raises(FileExistsError):
        write_json(out, {})
    nested = tmp_path / "new" / "dir" / "r.json"  # the README writes to out/ on a fresh checkout
    write_json(nested, {"a": 1}, make_folder=True)
    assert json.loads(nested.read_text()) == {"a": 1}


@pytest.mark.parametrize("args,message", [
    (["--levels", "-1"], "--levels: must be >= 2"),
    (["--order", "0"], "--order: must be >= 1"),
    (["--levels", "x"], "expected an integer"),
    (["--nu", "0.5"], "nu must satisfy"),
    (["--variant", "free"], "invalid choice"),
    (["--gamma", "2"], "--gamma needs --mesh graded"),
])
def test_bad_input_is_a_clear_error(args, message, tmp_path):
    # run outside the repository: from its root, "-m ngfracture" would import the
    # uncompiled source tree instead of the installed package
    env = dict(os.environ)
    if env.get("PYTHONPATH"):
        env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in env["PYTHONPATH"].split(os.pathsep))
    proc = subprocess.run([sys.executable, "-m", "ngfracture", "verify", "lshape", *args],
                          capture_output=True, text=True, cwd=tmp_path, env=env)
    assert proc.returncode == 2
    assert message in proc.stderr
    assert "Traceback" not in proc.stderr
