#!/usr/bin/env python3
"""IV-B at r = 1: an autoencoder of the paper's architecture built by hand (JAX, float64).

`scripts/ae_fan_code.py` showed that the paper's r = 1 decoder can hold a fan-shaped code well
enough for Table I and that what fails is the encoder: the code of a 2-D family on a 1-D curve is
a staircase that a trained tanh encoder does not tear sharply. Here both halves are *built* from
what IV-B's snapshots are, to learn whether the paper's 7-hidden-layer r = 1 network
(148-74-37-18-1-18-37-74-148, tanh, linear code and output) can reach Table I's 4.81 at all, and
at what weights. The follower moment's internal moment at s is the part of the pulse beyond s, so
the curvature is a smoothed step, linear in the moment M and zero beyond the load:

    x(s; c, M) = (M / EI) G(s; c),   G = 1 before the pulse, 0 after it,

and "the load reaches past s_k" is "the curvature at s_k is not zero": |x(s_k)| > ε, whatever the
sign and size of M. The code has K passes, one per bin of the centre between the K − 1 tears
s_k = k L / K + w/2; in pass j it runs along the moment, alternately outwards and inwards, so that
consecutive passes meet at their outer ends: u = ½ + j + (−1)^j m, m = 0.96 x(0) / (2 max|x(0)|)
(the factor keeps every code 0.02 away from a pass end), and the code is u / (K/2) − 1.

Encoder (nothing fitted):
- layer 1: per tear two units tanh(A (x(s_k) ∓ ε)), whose half difference plus one is the
  indicator I_k ∈ {0, 1} of |x(s_k)| > ε (a bump detector); one unit α x(0) in its linear range;
- layer 2: per tear a gate tanh(β m + B (I_k − 1)) = β I_k m + (I_k − 1) + O(β³) when I_k is 0
  or 1; one unit δ P in its linear range, P the part of u linear in m and the I_k;
- layer 3 and the code: u through one unit in its linear range.

Decoder: layer 1 passes u (linear range); layer 2 holds the K − 1 steps tanh(S (u − b)) between
passes; layer 3 the gates tanh(β (u − j − ½) + B (I_j − 1)) of every pass (I_j from the steps)
and the steps again, so that the output layer spans every per-pass affine function of the moment;
the output layer is the least-squares fit on the training rows (with `--output-penalty`, the
minimiser of eq. (15) including its penalty on those weights). `--decoder fitted` fits a Glorot-initialised decoder to the same
codes instead (`--dec-epochs` Adam epochs at 3e-3 decaying to 3 %, `--dec-lbfgs` L-BFGS
iterations); `--whole-lbfgs N` then minimises eq. (15) over both halves from there (relaxation).

The RMSE is Table I's (every value of every snapshot, physical units), on the 90 % training rows,
the held-out 10 % and all rows, and on every row of `--test DATASET2` (another draw, unseen); `eq15_*` are the two terms of eq. (15) at the built network (scaled
units), `tear_samples` the rows some I_k of which is not within 0.01 of 0 or 1. One JSON line:

    .venv/bin/python scripts/ae_constructed_encoder.py DATASET --tears 23

DATASET is `reproduce iv-b`'s (`gvsrom dataset soft-beam --random
loads.distributed.0.center=0:0.8 --random loads.distributed.0.magnitude=-5:5 --samples 5000
--seed 1`).
"""

import argparse
import json
import time
import tomllib
from pathlib import Path

import numpy as np

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

from ae_fan_code import fit, forward, glorot, squares  # noqa: E402
from ae_reference import load  # noqa: E402


def constructed_encoder(x, s, tears, a, eps, beta, big, delta, sizes, shrink=0.96):
    """Encoder weights acting on physical strains x (rows × n) at arc lengths s (module docs)."""
    n = x.shape[1]
    x0max = np.abs(x[:, 0]).max()  # x: the training rows
    alpha = 0.1 / x0max  # α x(0) ≤ 0.1: tanh is linear to 0.3 %
    # tear k at the grid point nearest to s_k (the curvature there is zero until the pulse's far
    # end passes it)
    idx = [int(np.argmin(np.abs(s - t))) for t in tears]
    K1 = len(idx)
    w1, b1 = np.zeros((n, sizes[1])), np.zeros(sizes[1])
    for k, j in enumerate(idx):
        w1[j, 2 * k] = a
        b1[2 * k] = -a * eps
        w1[j, 2 * k + 1] = a
        b1[2 * k + 1] = a * eps
    lin = 2 * K1
    w1[0, lin] = alpha
    # layer 2: I_k = 1 + (h[2k] − h[2k+1]) / 2, m = h[lin] / (2 α x0max)
    w2, b2 = np.zeros((sizes[1], sizes[2])), np.zeros(sizes[2])
    m_of_h = shrink / (2 * alpha * x0max)  # |m| ≤ shrink / 2: no code at a pass end
    for k in range(K1):
        # gate: β m + B (I_k − 1) = β m_of_h h_lin + B (h⁺ − h⁻)/2
        w2[lin, k] = beta * m_of_h
        w2[2 * k, k] = big / 2
        w2[2 * k + 1, k] = -big / 2
    # linear unit: δ P, P = m + Σ_k I_k (1 − 2(−1)^k / β) with k counted from 1
    P = K1
    w2[lin, P] = delta * m_of_h
    for k in range(K1):
        sign = (-1) ** (k + 1)
        c = 1 - 2 * sign / beta
        w2[2 * k, P] += delta * c / 2
        w2[2 * k + 1, P] -= delta * c / 2
        b2[P] += delta * c
    # layer 3: z = ½ + P + Σ_k 2(−1)^k (g_k + 1)/β, through one unit δ (z − z_mid)
    z_mid = (K1 + 1) / 2
    w3, b3 = np.zeros((sizes[2], sizes[3])), np.zeros(sizes[3])
    w3[P, 0] = 1.0  # tanh(δP)/δ ≈ P
    for k in range(K1):
        sign = (-1) ** (k + 1)
        w3[k, 0] = delta * 2 * sign / beta
        b3[0] += delta * 2 * sign / beta
    b3[0] += delta * (0.5 - z_mid)
    # code: z scaled to [−1, 1]
    w4 = np.zeros((sizes[3], 1))
    w4[0, 0] = 1.0 / delta / z_mid
    b4 = np.zeros(1)
    return [(w1, b1), (w2, b2), (w3, b3), (w4, b4)]


def constructed_decoder_hidden(K, sizes, delta, steep, beta, big):
    """Decoder layers 1-3 (code → features); the output layer is solved by least squares.

    u = (z + 1) K / 2 ∈ [0, K] is the pass coordinate (pass j is [j, j + 1]). Layer 1 passes u in
    its linear range; layer 2 holds the K − 1 steps S_b = tanh(A (u − b)) between passes and u
    again; layer 3 holds, for every pass, the gate tanh(β (u − j − ½) + B (I_j − 1)) with
    I_j = (S_j − S_{j+1}) / 2 (S_0 = 1, S_K = −1), and the steps again (tanh(S_b) = ±0.76). The
    output layer's span then holds every per-pass affine function of u, i.e. of the moment.
    """
    d1, d2, d3 = sizes[1], sizes[2], sizes[3]
    w1, b1 = np.zeros((1, d1)), np.zeros(d1)
    w1[0, 0] = delta * K / 2
    b1[0] = delta * K / 2  # h0 = tanh(δ u)
    w2, b2 = np.zeros((d1, d2)), np.zeros(d2)
    for b in range(1, K):
        w2[0, b - 1] = steep / delta
        b2[b - 1] = -steep * b
    lin = K - 1
    w2[0, lin] = 1.0  # tanh(h0) ≈ δ u
    w3, b3 = np.zeros((d2, d3)), np.zeros(d3)

    def add_I(col, j, gain):
        # gain · I_j = gain (S_j − S_{j+1}) / 2, S_0 = 1, S_K = −1 as constants
        for bb, sgn in ((j, 0.5), (j + 1, -0.5)):
            if bb == 0:
                b3[col] += gain * sgn
            elif bb == K:
                b3[col] -= gain * sgn
            else:
                w3[bb - 1, col] += gain * sgn

    for j in range(K):
        w3[lin, j] = beta / delta
        b3[j] = -beta * (j + 0.5) - big
        add_I(j, j, big)
    for b in range(1, K):
        w3[b - 1, K + b - 1] = 1.0  # tanh(±1): the step again, two-valued
    return [(w1, b1), (w2, b2), (w3, b3)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path)
    ap.add_argument("--tears", type=int, default=23, help="K − 1: the code has K passes")
    ap.add_argument("--sharpness", type=float, default=4000.0, help="A, per 1/m of curvature")
    ap.add_argument("--threshold", type=float, default=1.5, help="ε, 1/m")
    ap.add_argument("--beta", type=float, default=0.2)
    ap.add_argument("--gate", type=float, default=20.0, help="B")
    ap.add_argument("--delta", type=float, default=1e-4)
    ap.add_argument("--decoder", choices=["constructed", "fitted"], default="constructed")
    ap.add_argument("--steepness", type=float, default=500.0, help="decoder steps, per pass")
    ap.add_argument("--first-layer-scale", type=float, default=30.0)
    ap.add_argument("--dec-epochs", type=int, default=0)
    ap.add_argument("--dec-lbfgs", type=int, default=0)
    ap.add_argument("--whole-lbfgs", type=int, default=0)
    ap.add_argument("--lambda", dest="lam", type=float, default=1e-4)
    ap.add_argument("--output-penalty", action="store_true",
                    help="the decoder's output layer minimises eq. (15) with its penalty")
    ap.add_argument("--test", type=Path, help="a second dataset of the same scenario, unseen")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    t0 = time.time()

    x = load(a.dataset)
    rows, n = x.shape
    scenario = tomllib.loads(json.loads((a.dataset / "meta.json").read_text())["scenario_toml"])
    length = sum(d["length"] for d in scenario["divisions"])
    half_width = scenario["loads"]["distributed"][0]["width"] / 2
    s = np.load(a.dataset / "strain_x.npy")  # arc length of every strain value
    if len(s) != n:
        raise SystemExit(f"{a.dataset}: {len(s)} arc lengths for {n} strain values")
    K = a.tears + 1
    if not 2 <= K <= n // 4:
        raise SystemExit(f"--tears {a.tears}: expected 1 to {n // 4 - 1} (layer widths)")
    tears = [k * length / K + half_width for k in range(1, K)]
    tears = [min(t, s[-2]) for t in tears]

    rng = np.random.default_rng(a.seed)
    order = rng.permutation(rows)
    n_val = rows // 10
    val, train = order[:n_val], order[n_val:]
    mean = x[train].mean(0)
    scale = float(np.sqrt(np.mean(x[train].std(0) ** 2)))
    y_np = (x - mean) / scale
    y = jnp.asarray(y_np)
    sizes = [n, n // 2, n // 4, n // 8, 1]
    enc_phys = constructed_encoder(x[train], s, tears, a.sharpness, a.threshold, a.beta, a.gate,
                                   a.delta, sizes)
    # to scaled inputs: x = scale y + mean
    (w1, b1) = enc_phys[0]
    enc = [(jnp.asarray(w1 * scale), jnp.asarray(b1 + mean @ w1))] + [
        (jnp.asarray(w), jnp.asarray(b)) for w, b in enc_phys[1:]]
    z = np.asarray(forward(enc, y))
    h1 = np.tanh(x @ enc_phys[0][0] + enc_phys[0][1])
    ind = 1 + (h1[:, 0:2 * a.tears:2] - h1[:, 1:2 * a.tears:2]) / 2
    bins = np.round(ind).sum(1).astype(int)
    out = {"rows": rows, "passes": K, "code_min": float(z.min()), "code_max": float(z.max()),
           "bin_counts": np.bincount(bins, minlength=K).tolist(),
           "tear_samples": int((np.abs(ind - np.round(ind)) > 0.01).any(1).sum()),
           "encoder_weights_sq": float(squares(enc))}

    if a.decoder == "constructed":
        hidden = constructed_decoder_hidden(K, sizes[::-1], a.delta, a.steepness, a.beta, a.gate)
        dec = [(jnp.asarray(w), jnp.asarray(b)) for w, b in hidden]
        feats = np.asarray(forward(dec + [(jnp.eye(sizes[1]), jnp.zeros(sizes[1]))],
                                   jnp.asarray(z)))
        f_tr = np.c_[feats[train], np.ones(len(train))]
        # plain least squares (the minimum-norm solution: unused units get no weight), or with
        # eq. (15)'s penalty on the output weights, not the bias (eq. (15) is the mean over rows
        # and values plus λ/n Σ‖W‖²; times rows · n: the squared residual plus λ · rows Σ‖W‖²)
        reg = (a.lam * len(train) if a.output_penalty else 0.0) * np.eye(f_tr.shape[1])
        reg[-1, -1] = 0.0
        sol = np.linalg.lstsq(np.r_[f_tr, np.sqrt(reg)],
                              np.r_[y_np[train], np.zeros((len(reg), n))], rcond=None)[0]
        dec.append((jnp.asarray(sol[:-1]), jnp.asarray(sol[-1])))
        out["ls_rmse_train"] = float(np.sqrt(np.mean((f_tr @ sol - y_np[train]) ** 2)) * scale)
        out["features_used"] = int((np.abs(feats).max(0) > 0).sum())
    else:
        dec = glorot(sizes[::-1], jax.random.PRNGKey(a.seed), a.first_layer_scale)
    lam = a.lam / n
    zj = jnp.asarray(z)

    def rmse(pred, rows_) -> float:
        return float(np.sqrt(np.mean((np.asarray(pred)[rows_] - y_np[rows_]) ** 2)) * scale)

    dec = fit(dec, lambda p, i: jnp.mean((forward(p, zj[i]) - y[i]) ** 2) + lam * squares(p),
              train, a.dec_epochs, a.dec_lbfgs, 3e-3, rng)
    pred = forward(dec, zj)
    out["rmse_train"] = rmse(pred, train)
    out["rmse_validation"] = rmse(pred, val)
    out["rmse_all"] = rmse(pred, np.arange(rows))
    out["seconds_decoder"] = time.time() - t0
    out["decoder_weights_sq"] = float(squares(dec))
    if a.test:
        xt = load(a.test)
        yt = (xt - mean) / scale
        rec = np.asarray(forward(dec, forward(enc, jnp.asarray(yt))))
        out["rmse_test"] = float(np.sqrt(np.mean((rec - yt) ** 2)) * scale)
        out["test_rows"] = len(xt)
    out["eq15_reconstruction"] = float(np.mean((np.asarray(pred)[train] - y_np[train]) ** 2))
    out["eq15_penalty"] = lam * (out["encoder_weights_sq"] + out["decoder_weights_sq"])
    if a.whole_lbfgs:
        def whole(p, i):
            rec = forward(p[1], forward(p[0], y[i]))
            return jnp.mean((rec - y[i]) ** 2) + lam * (squares(p[0]) + squares(p[1]))

        enc, dec = fit((enc, dec), whole, train, 0, a.whole_lbfgs, 0.0, rng)
        pred = forward(dec, forward(enc, y))
        out["whole_rmse_validation"] = rmse(pred, val)
        out["whole_encoder_weights_sq"] = float(squares(enc))
        out["whole_decoder_weights_sq"] = float(squares(dec))
        out["whole_rmse_all"] = rmse(pred, np.arange(rows))
    out["seconds"] = time.time() - t0
    print(json.dumps({**vars(a), **out}, default=str))


if __name__ == "__main__":
    main()
