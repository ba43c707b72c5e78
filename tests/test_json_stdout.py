"""Every command with --json prints one JSON document on stdout and nothing else (issue 26):
each runs in a new process, as a user or a script would run it, so that Taichi's start-up lines
("[Taichi] version ...", "[Taichi] Starting on arch=...", printed again when the backend
restarts for the f64 variant) would show up on stdout if they went there. Sized to be cheap:
tiny presets, a short end time, --max-steps. `sweep` has no --json (it writes regime.json)."""
import json
import os
import subprocess
import sys

import pytest

SHORT = ["--set", "scene.t_end=5e-5", "--set", "scene.frame_interval=2.5e-5"]


def run_cli(args, tmp_path, timeout=420):
    env = dict(os.environ)
    env.pop("CROWNDEMO_ARCH", None)
    proc = subprocess.run([sys.executable, "-m", "crowndemo", *args], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=timeout)
    return proc


def one_document(proc):
    """stdout read by json.loads, which refuses anything before or after the document."""
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.lstrip().startswith(("{", "[")), proc.stdout[:300]
    return json.loads(proc.stdout)


@pytest.mark.parametrize("args", [
    ["presets", "--json"],
    ["info", "quick-2d", "--json"],
    ["info", "--dim", "2", "--l0", "1e-3", "--json"],
    ["scene", "dam-break", "--dim", "2", "--t-end", "0.001", "--json", "--quiet"],
    ["run", "quick-2d", "--max-steps", "3", "--json", "--quiet", *SHORT],
    ["bench", "--n", "2000", "--steps", "2", "--no-stages", "--json"],
    ["validate", "--list", "--json"],
], ids=lambda a: " ".join(a[:2]))
def test_json_stdout_is_one_document(args, tmp_path):
    data = one_document(run_cli(args, tmp_path))
    assert data


def test_record_json_is_one_document(tmp_path):
    proc = run_cli(["record", "quick-2d", "--recordings", str(tmp_path), "--resolution",
                    "320x180", "--no-video", "--json", "--quiet", *SHORT], tmp_path)
    meta = one_document(proc)
    assert meta["complete"] and len(meta["frames"]) == 3          # t = 0, 25, 50 us
    saved = json.loads((tmp_path / "quick-2d" / "metadata.json").read_text())
    assert (meta["status"], meta["frames"]) == (saved["status"], saved["frames"])


def test_validate_json_with_a_backend_restart_is_one_document(tmp_path):
    """shear-wave-2d's quick plan runs its f64 variant: the backend restarts in f64 and then
    back in f32, and each start's banner goes to stderr."""
    proc = run_cli(["validate", "shear-wave-2d", "--quick", "--json", "--out", str(tmp_path)],
                   tmp_path)
    data = one_document(proc)
    assert proc.stderr.count("[Taichi] Starting on arch=") == 3   # f32, f64, f32 again
    rows = data["cases"]
    assert [(r["case"], r["variant"]) for r in rows] == [("shear-wave-2d", "base"),
                                                          ("shear-wave-2d", "f64")]
    # the exact decay rate nu k^2 (water, lambda = 2 mm), measured within the README's 0.35 %
    nu, k = 1.0e-6, 2 * 3.141592653589793 / 2.0e-3
    for r in rows:
        assert r["outcome"] == "ok" and r["reference"] == pytest.approx(nu * k * k, rel=1e-3)
        assert abs(r["measured"] / r["reference"] - 1) < 0.01
    assert data == json.loads((tmp_path / "validation.json").read_text())
