#!/usr/bin/env python3
"""Levenberg–Marquardt (Gauss–Newton with conjugate gradients) on a whole autoencoder.

An experiment on IV-B's r = 1 cell (docs/assumptions.md): does a second-order method on the
full-batch loss fold a 1-D code through the 2-D family faster than Adam and L-BFGS? It continues
from the weights `scripts/ae_reference.py --save W.npy` kept, on the same rows (the same seeded
split and the `physical` scaling, which `--loss` must match), and minimises the same loss, eq. (15):

    f(θ) = (1/(N n)) Σ_b ‖D(E(y_b)) − y_b‖² + (λ/n) Σ ‖W‖²

by steps `δ` solving `(2 JᵀJ + 2(λ/n) P + μ I) δ = −∇f` with `--cg-iterations` conjugate-gradient
iterations, each a Jacobian–vector and a vector–Jacobian product over all training rows (`J` the
Jacobian of the scaled residuals, `P` the projection onto the weights, `μ` the damping: divided by
3 after a step that lowers `f`, multiplied by 4 and the step refused otherwise). It prints the
training and validation RMSE in physical units every ten steps and the RMSE over the whole dataset
at the end.

    .venv/bin/python scripts/ae_reference.py ivb --latent 1 --epochs 1500 --learning-rate 1e-3 \
        --final-lr-factor 0.03 --loss physical --save adam.npy
    .venv/bin/python scripts/ae_gauss_newton.py ivb adam.npy --latent 1 --steps 400
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ae_reference import architecture, forward, init, load  # noqa: E402

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
from jax.flatten_util import ravel_pytree  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path)
    ap.add_argument("weights", type=Path, help="flattened weights from ae_reference.py --save")
    ap.add_argument("--latent", type=int, default=1)
    ap.add_argument("--hidden-layers", type=int, default=7)
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--cg-iterations", type=int, default=50)
    ap.add_argument("--lambda", dest="lam", type=float, default=1e-4)
    ap.add_argument("--validation-fraction", type=float, default=0.1)
    ap.add_argument("--seed", type=int, default=0, help="the split seed ae_reference.py used")
    args = ap.parse_args()

    x = load(args.dataset)
    rows, n = x.shape
    order = np.random.default_rng(args.seed).permutation(rows)
    n_val = int(rows * args.validation_fraction)
    val, train = order[:n_val], order[n_val:]
    mu = x[train].mean(0)
    c = float(np.sqrt(np.mean(x[train].std(0) ** 2)))
    y = jnp.asarray((x - mu) / c)
    y_train, y_val = y[train], y[val]

    sizes = architecture(n, args.latent, args.hidden_layers)
    half = (args.hidden_layers + 1) // 2
    flags = [k + 1 < half for k in range(half)] * 2
    template = init(sizes, jax.random.PRNGKey(0))
    _, unravel = ravel_pytree(template)
    theta = jnp.asarray(np.load(args.weights))
    # 1 on the weights, 0 on the biases: eq. (15) regularises the weights only
    mask = ravel_pytree([(jnp.ones_like(w), jnp.zeros_like(b)) for w, b in template])[0]
    if theta.shape != mask.shape:
        raise SystemExit(
            f"{args.weights}: {theta.shape[0]} values, the {'-'.join(map(str, sizes))} network "
            f"has {mask.shape[0]}"
        )
    rows_scale = 1.0 / np.sqrt(y_train.size)
    reg = args.lam / n

    def residual(t):
        return ((forward(unravel(t), y_train, flags) - y_train) * rows_scale).ravel()

    @jax.jit
    def objective(t):
        r = residual(t)
        return r @ r + reg * jnp.sum((mask * t) ** 2)

    gradient = jax.jit(jax.grad(objective))

    @jax.jit
    def curvature(t, v, damping):
        _, jv = jax.jvp(residual, (t,), (v,))
        _, vjp = jax.vjp(residual, t)
        return 2.0 * vjp(jv)[0] + 2.0 * reg * mask * v + damping * v

    @jax.jit
    def rmse(t, data):
        return jnp.sqrt(jnp.mean((forward(unravel(t), data, flags) - data) ** 2)) * c

    def solve(t, g, damping):
        d = jnp.zeros_like(g)
        r = -g
        p = r
        rs = r @ r
        for _ in range(args.cg_iterations):
            ap_ = curvature(t, p, damping)
            alpha = rs / (p @ ap_)
            d = d + alpha * p
            r = r - alpha * ap_
            rs_new = r @ r
            if rs_new < 1e-10 * (g @ g):
                break
            p = r + rs_new / rs * p
            rs = rs_new
        return d

    damping, f, t0 = 1e-3, float(objective(theta)), time.perf_counter()
    print(f"start      training {float(rmse(theta, y_train)):.4f}, validation "
          f"{float(rmse(theta, y_val)):.4f}", flush=True)
    for step in range(1, args.steps + 1):
        g = gradient(theta)
        trial = theta + solve(theta, g, damping)
        f_trial = float(objective(trial))
        if f_trial < f:
            theta, f, damping = trial, f_trial, max(damping / 3.0, 1e-9)
        else:
            damping *= 4.0
        if step % 10 == 0:
            print(f"step {step:5d} training {float(rmse(theta, y_train)):.4f}, validation "
                  f"{float(rmse(theta, y_val)):.4f}, damping {damping:.2e}, "
                  f"{time.perf_counter() - t0:.0f} s", flush=True)
    print(f"RMSE       {float(rmse(theta, y)):.4e} over all {rows} snapshots (physical units), "
          f"{args.steps} steps in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
