#!/usr/bin/env python3
"""The kinetic-energy metric of a dataset's rows, for `scripts/ae_rates_reference.py --kinetic`.

Writes PREFIX_B.npy, the basis at the computational points (`x = q B`, fitted by least squares from
the dataset's own `q.npy` and `strain.npy` and checked to be exact), and PREFIX_L.npy, the Cholesky
factor `L` of the mass matrix `M(q) = L Lᵀ` at every row's configuration (`gvsrom.Robot.mass_matrix`),
so that a strain-rate error `e` weighs `q̇ᵀ M q̇ = ‖(e B⁺) L‖²`.

    target/py-venv/bin/python scripts/kinetic_metric.py DATASET SCENARIO PREFIX
"""
import sys
import numpy as np
import gvsrom

dataset, scenario, prefix = sys.argv[1:4]
robot = gvsrom.Scenario.preset(scenario).build()
q = np.load(f"{dataset}/q.npy")
x = np.load(f"{dataset}/strain.npy")
x = x.reshape(x.shape[0], -1)
B = np.linalg.lstsq(q, x, rcond=None)[0]
err = np.abs(q @ B - x).max() / np.abs(x).max()
if err > 1e-9:
    sys.exit(f"strain is not linear in q ({err:.2e}): not a dataset of this basis")
L = np.stack([np.linalg.cholesky(robot.mass_matrix(qi)) for qi in q])
np.save(f"{prefix}_B.npy", B)
np.save(f"{prefix}_L.npy", L)
print(f"{prefix}_B.npy {B.shape}, {prefix}_L.npy {L.shape} (x = q B to {err:.1e})")
