"""A reduced model in the control loop: the IV-A arm's tip follows a height, by inverse statics.

The single-tendon arm (the paper's IV-A) is to move its tip along a height reference z_ref(t), a
sine between the heights of its equilibria at −1 and −5 N. At every control period (100 Hz) the
controller solves the *statics* of a model for the tension whose equilibrium puts the tip at
z_ref(t) (a feedforward by inverse statics: secant steps on the tension warm-started from the
last period, each an equilibrium of the model),
and may add a PI correction on the tip height it measures on the arm. The arm itself is the
full model (HOM) in dynamics (``simulate(controller=…)``, the tension held over each period).

Laws compared, each run on the HOM:

- ``rom``: the feedforward from the 1-DOF autoencoder ROM's statics (the paper's AE-1, trained
  here on 200 equilibria), no feedback;
- ``rom+pi``: the same with a PI on the measured tip height;
- ``hom+pi``: the feedforward from the full model's statics, with the same PI: what the ROM
  replaces.

It prints the tracking errors (% of the arm's length) and the controller's time per call against
the 10 ms period (docs/linearize.md has the table of a full run). Writes the dataset, the model
and the three runs under OUT.

    python crates/gvsrom-py/examples/rom_tracking.py OUT [--duration 6] [--epochs 300]
"""

import argparse
import time
from pathlib import Path

import numpy as np

import gvsrom

U_RANGE = (-6.0, 3.0)  # the tensions of the paper's IV-A dataset [N]
U_PULL = (-6.0, 0.0)   # what the law may command: the tendon only pulls [N]


class Equilibria:
    """A model's tip height at equilibrium under a tension: one `Robot.statics` solve, which
    starts the full model from the straight rod (its load ramp) and a reduced model from its
    training anchors at that tension. A Newton from the last equilibrium, written here with
    `statics_residual` and `statics_jacobian`, was slower for both models (7.1 and 1.8 ms per
    call of the law, against 4.1 and 0.7): each of its iterations crosses into Python three
    times, where a native solve runs whole."""

    def __init__(self, robot):
        self.robot = robot
        self.iterations = 0

    def tip_height(self, u):
        eq = self.robot.statics([u])
        self.iterations += eq.iterations
        return eq.tip_position[2]


class InverseStatics:
    """The tension whose equilibrium puts the tip at a height, by secant steps on u.

    Each call starts from the last call's answer and slope ∂z/∂u, so a slowly moving reference
    costs one or two equilibria per period. A call that stops short of `tol` (the reference out
    of the tendon's reach, or 20 steps) is counted in `unconverged`.
    """

    def __init__(self, equilibria, u0, tol=1e-7):
        self.equilibria, self.tol = equilibria, tol
        self.u, self.z = u0, equilibria.tip_height(u0)
        self.slope = (equilibria.tip_height(u0 - 0.05) - self.z) / -0.05
        self.solves = self.unconverged = 0

    def __call__(self, z_ref):
        u0, z0 = self.u, self.z
        for _ in range(20):
            if abs(z0 - z_ref) < self.tol:
                break
            u1 = float(np.clip(u0 + (z_ref - z0) / self.slope, *U_PULL))
            if u1 == u0:
                break  # the reference is beyond what the tendon reaches
            z1 = self.equilibria.tip_height(u1)
            self.solves += 1
            if z1 != z0:
                self.slope = (z1 - z0) / (u1 - u0)
            u0, z0 = u1, z1
        if abs(z0 - z_ref) >= self.tol:
            self.unconverged += 1
        self.u, self.z = u0, z0
        return u0


class Law:
    """u = u_ff(z_ref) + (k_p e + k_i ∫e) / g, e = z_ref − z (the tip height of the arm's state),
    g = ∂z/∂u at the reference's middle; the integral stops while the tension is clipped to what
    the tendon can do (anti-windup). The time spent in each call is kept."""

    def __init__(self, robot, feedforward, z_ref, gain, pi=True, kp=2.0, ki=20.0):
        self.robot, self.feedforward, self.z_ref = robot, feedforward, z_ref
        self.gain, self.pi, self.kp, self.ki = gain, pi, kp, ki
        self.integral, self.last_t, self.clipped, self.times = 0.0, None, False, []

    def __call__(self, t, q, qd):
        start = time.perf_counter()
        z_ref = self.z_ref(t)
        u = self.feedforward(z_ref)
        if self.pi:
            e = z_ref - self.robot.forward(q)["position"][-1, 2]
            if self.last_t is not None and not self.clipped:
                self.integral += e * (t - self.last_t)
            self.last_t = t
            u += (self.kp * e + self.ki * self.integral) / self.gain
        held = float(np.clip(u, *U_PULL))
        self.clipped = held != u
        self.times.append(time.perf_counter() - start)
        return held


def reduced_model(robot, out, epochs, seed):
    """The paper's AE-1 (7 hidden layers) on 200 equilibria over its tension range."""
    data = gvsrom.dataset(robot.scenario, out / "data",
                          sweep={"tendons.0.tension": U_RANGE}, samples=200)
    return gvsrom.train(data, out / "ae1", latent=1, hidden_layers=7, epochs=epochs, seed=seed)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="a new directory for the data, model and runs")
    parser.add_argument("--duration", type=float, default=6.0, help="simulated time [s]")
    parser.add_argument("--epochs", type=int, default=300, help="the autoencoder's Adam epochs")
    parser.add_argument("--period", type=float, default=3.0, help="the reference's period [s]")
    parser.add_argument("--seed", type=int, default=0, help="the training's seed")
    parser.add_argument("--kp", type=float, default=2.0, help="the PI's proportional gain")
    parser.add_argument("--ki", type=float, default=20.0, help="the PI's integral gain [1/s]")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=False)

    hom = gvsrom.Scenario.preset("single-tendon").build()
    rom = hom.with_model(reduced_model(hom, args.out, args.epochs, args.seed))
    length = hom.length
    z_lo, z_hi = (hom.statics([u]).tip_position[2] for u in (-1.0, -5.0))
    z_mid, amp = (z_lo + z_hi) / 2, (z_hi - z_lo) / 2

    def z_ref(t):
        return z_mid - amp * np.cos(2 * np.pi * t / args.period)

    # the feedback's scale: ∂z/∂u of the full model at the reference's middle
    full = Equilibria(hom)
    u_mid = InverseStatics(full, -3.0)(z_mid)
    gain = (full.tip_height(u_mid + 1e-3) - full.tip_height(u_mid - 1e-3)) / 2e-3
    # how well the ROM's inverse statics agrees with the full model's, over the reference
    heights = z_ref(np.linspace(0, args.period / 2, 7))
    by_rom = InverseStatics(Equilibria(rom), -1.0)
    by_hom = InverseStatics(Equilibria(hom), -1.0)
    du = max(abs(by_rom(z) - by_hom(z)) for z in heights)
    print(f"reference  tip height {z_lo:.4f} … {z_hi:.4f} m, period {args.period} s")
    print(f"inverse    ROM against full-model statics over the reference: |Δu| ≤ {du:.2e} N")

    u0 = InverseStatics(Equilibria(hom), -1.0)(z_ref(0.0))
    q0 = hom.statics([u0]).q

    def inverse(model):
        return InverseStatics(Equilibria(model), u0)

    laws = {
        "rom": Law(hom, inverse(rom), z_ref, gain, pi=False),
        "rom+pi": Law(hom, inverse(rom), z_ref, gain, kp=args.kp, ki=args.ki),
        "hom+pi": Law(hom, inverse(hom), z_ref, gain, kp=args.kp, ki=args.ki),
    }
    h = 0.01
    rows = {}
    print("| law | tip error RMS | max | tension | law's time per call: mean | max | "
          "equilibria per call | Newton iterations per call | unconverged calls |")
    print("|---|---:|---:|---|---:|---:|---:|---:|---:|")
    for name, law in laws.items():
        tr = hom.simulate(args.duration, sample_rate=1 / h, controller=law, q0=q0,
                          out=args.out / name)
        err = np.abs(tr["tip_position"][:, 2] - z_ref(tr["t"])) / length
        u = tr["u"][:-1, 0]
        times = np.array(law.times)
        ff = law.feedforward
        solves = ff.solves / len(times)
        newton = ff.equilibria.iterations / len(times)
        rows[name] = {"rms": float(np.sqrt((err ** 2).mean())), "max": float(err.max()),
                      "mean_time": float(times.mean()), "solves": solves, "newton": newton,
                      "unconverged": ff.unconverged}
        print(f"| {name} | {100 * rows[name]['rms']:.3f} % L | {100 * err.max():.3f} % L | "
              f"{u.min():.2f} … {u.max():.2f} N | {1e3 * times.mean():.3f} ms | "
              f"{1e3 * times.max():.3f} ms | {solves:.2f} | {newton:.2f} | {ff.unconverged} |")
    return rows, du


if __name__ == "__main__":
    main()
