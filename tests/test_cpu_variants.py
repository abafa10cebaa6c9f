"""Results that hold on every CPU: a seed's sea, and runs as other CPUs' numpy and OpenBLAS
compute them (``cosim.studies.cpu_variants``; the whole audit: python -m cosim.accuracy
--cpus)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from cosim.studies.cpu_variants import VARIANTS, audit
from helpers import WAVE_DIGESTS

NUMPY_AND_BLAS = ["numpy without AVX-512", "numpy at its baseline", "OpenBLAS SkylakeX",
                  "OpenBLAS Sandybridge"]
_CHILD = f"""
import json, math, sys
sys.path.insert(0, {str(Path(__file__).parent)!r})
import numpy as np
from helpers import WAVE_DIGESTS, wave_digest
x = np.random.default_rng(1).uniform(-60.0, 60.0, 20_000)
print(json.dumps({{"digests": {{str(s): wave_digest(s) for s in WAVE_DIGESTS}},
                  "np.sin is libm's": bool((np.sin(x) == [math.sin(v) for v in x]).all())}}))
"""


def test_a_seeds_sea_has_the_same_bits_under_every_variant():
    """Every variant, glibc without FMA included: the realisation uses exactly rounded
    operations only. And numpy's sin, on the step path, is the C library's sin there."""
    def child(variant: str) -> dict:
        done = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True,
                              timeout=120, env={**os.environ, **VARIANTS[variant]})
        assert done.returncode == 0, (variant, done.stderr)
        return json.loads(done.stdout)

    with ThreadPoolExecutor(2) as pool:
        results = dict(zip(VARIANTS, pool.map(child, VARIANTS)))
    expected = {str(seed): digest for seed, digest in WAVE_DIGESTS.items()}
    for variant, result in results.items():
        assert result == {"digests": expected, "np.sin is libm's": True}, variant


def test_runs_are_bit_identical_under_other_cpus_numpy_and_openblas():
    """Every column of every row, a calm PD run and the chattering SMC in waves, 60 s."""
    results = audit(["calm_pd", "waves_smc"], NUMPY_AND_BLAS, stop_time=60.0)
    assert results == {s: dict.fromkeys(NUMPY_AND_BLAS) for s in ("calm_pd", "waves_smc")}
