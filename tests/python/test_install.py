"""`cmake --install` of the build into a temporary prefix: the module imports from there."""
import os
import subprocess
import sys

import pytest

BUILD = os.environ.get("ROIFLOW_BUILD_DIR")


@pytest.mark.skipif(not BUILD, reason="ROIFLOW_BUILD_DIR not set")
def test_installed_module_imports_and_computes(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", BUILD, "--prefix", str(prefix)], check=True,
                   capture_output=True)
    site = prefix / "lib" / "python3" / "dist-packages"
    assert any(p.name.startswith("roiflow.") and p.suffix == ".so" for p in site.iterdir())
    code = ("import numpy as np, roiflow; a = (np.indices((64, 80)).sum(0) * 7 % 251)"
            ".astype(np.uint8); f = roiflow.dense_flow(a, a); print(roiflow.__file__, f.shape)")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    r = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True,
                       text=True, check=True)
    assert r.stdout.startswith(str(site)), r.stdout
    assert "(64, 80, 2)" in r.stdout
