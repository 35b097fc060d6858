"""An LQR on the IV-A arm's tip, designed on its linearization, run on the nonlinear model.

The study of docs/linearize.md ("For control: an LQR on the linearization"): the single-tendon arm
at its −3 N equilibrium, kicked along its first mode, with the tension held at −3 N and with a
discrete LQR at 100 Hz (a sampled-data controller: ``simulate(controller=…)``). Prints the table
of the tip errors and writes both runs and their figures (``gvsrom.plot``: the tip, the tensions,
the rod) under OUT.

    python crates/gvsrom-py/examples/lqr_tip.py OUT [--duration 1.0]
"""

import argparse
from pathlib import Path

import numpy as np

import gvsrom


def discrete_lqr(Ad, Bd, Q, R, iterations=5000):
    """The gain K of u = −K x minimising Σ xᵀQx + uᵀRu for x⁺ = Ad x + Bd u (Riccati iteration)."""
    P = Q.copy()
    for _ in range(iterations):
        K = np.linalg.solve(R + Bd.T @ P @ Bd, Bd.T @ P @ Ad)
        P_next = Q + Ad.T @ P @ (Ad - Bd @ K)
        if np.abs(P_next - P).max() < 1e-12 * np.abs(P).max():
            return K
        P = P_next
    raise RuntimeError("the Riccati iteration did not converge")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="a new directory for the runs and their figures")
    parser.add_argument("--duration", type=float, default=1.0, help="simulated time [s]")
    args = parser.parse_args()

    robot = gvsrom.Scenario.preset("single-tendon").build()
    u0, h = -3.0, 0.01
    lin = robot.linearize(u=[u0], dt=h)
    Ad, Bd, C, x0 = lin["Ad"], lin["Bd"], lin["C"], lin["x0"]
    # the tip position weighted through C; a small weight on the whole state keeps Q definite
    K = discrete_lqr(Ad, Bd, 1e4 * C.T @ C + 1e-8 * np.eye(len(x0)), np.array([[1e-3]]))
    rho = max(abs(np.linalg.eigvals(Ad - Bd @ K)))
    n = robot.n_dof
    # the kick: q̇₀ along the first mode, the largest component of the tip's velocity 0.5 m/s
    phi = robot.modes(1, u=[u0])["shape"][0]
    qd_kick = 0.5 * phi / np.abs(C[:, :n] @ phi).max()
    tip0 = lin["tip_position"]
    laws = {
        "held": lambda t, q, qd: u0,
        "lqr": lambda t, q, qd: u0 - (K @ (np.concatenate([q, qd]) - x0))[0],
    }
    args.out.mkdir(parents=True, exist_ok=False)
    print(f"closed-loop spectral radius {rho:.3f} (open loop {lin['spectral_radius']:.3f})")
    print("| | tip error RMS | max | at half time | tension |")
    print("|---|---:|---:|---:|---|")
    for name, law in laws.items():
        tr = robot.simulate(args.duration, sample_rate=1 / h, controller=law, q0=x0[:n],
                            qd0=qd_kick, out=args.out / name)
        gvsrom.plot(args.out / name, args.out / f"{name}-figures")
        err = np.linalg.norm(tr["tip_position"][1:] - tip0, axis=1)
        u = tr["u"][:-1, 0]
        half = err[len(err) // 2 - 1]
        print(f"| {name} | {1e3 * np.sqrt((err ** 2).mean()):.3g} mm | {1e3 * err.max():.3g} mm | "
              f"{1e3 * half:.2g} mm | {u.min():.2f} … {u.max():.2f} N |")


if __name__ == "__main__":
    main()
