#!/usr/bin/env python3
"""soromox side of the tendon peer check: static equilibrium of a tendon-driven cantilever.

Problem: rod along world +x from the origin, L = 0.5 m, solid circle r = 0.01 m,
E = 1e7 Pa, G = E/3, rho = 1000 kg/m^3, base clamped (base_pose [0 0 0 1 0 0 0]),
no gravity.  One frictionless tendon over the whole length, anchored at the tip,
tension T = 2 N.  Routing in the local material frame (local x = backbone):
  --case const   offset (y, z) = (0, 0.008) m
  --case linear  offset z = 0.01 m at s = 0 -> 0.003 m at s = L (linear in s)
GVS: one segment, Legendre basis of degree --order in all six strains, --gauss
Gauss points (default 5).

soromox model (soromox 0.5.0, soromox/actuation/threadlike.py and
soromox/systems/gvs/core.py): ThreadlikeActuator.tendons(routing) has
coordinate_scale = -1, so its generalized force is
    tau_u = A(q) T,   A(q) = -(d l / d q)^T,
l(q) = int_0^L |d_s r + xi^(q) r| ds the routed path length (GVS._threadlike_path_lengths)
and d l/d q^T = int_0^L B(s)^T [r x t; t] ds (GVS._threadlike_moment_matrix),
both with the segment's Gauss rule.  This is the full virtual work -T dl of the
tendon (distributed load + tip anchor force), no separate tip term is added.
Equations of motion: M qdd = tau_u + tau_ext - C qd - G - K(q) - D qd, so the
static equilibrium solved here is  elastic_force(q) - actuation_force(q, [T]) = 0
(Newton with load continuation, Jacobian by jax.jacfwd; soromox has no statics solver).
"""
import argparse

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
import soromox as sx  # noqa: E402
from soromox.actuation import ThreadlikeActuator, ThreadlikeRouting  # noqa: E402
from soromox_statics import equilibrium  # noqa: E402

L, R, E, RHO, TENSION = 0.5, 0.01, 1e7, 1000.0, 2.0


def build(order, gauss, case):
    link = sx.LinkSpec.circular(length=L, radius=R, density=RHO,
                                reference_strain=[0, 0, 0, 1.0, 0, 0],
                                young_modulus=E, shear_modulus=E / 3)
    basis = sx.StrainBasisSpec(type="legendre", strain_selector=[1] * 6, basis_order=order)
    seg = sx.GVSSegment(link=link, joint=sx.JointSpec.fixed(), basis=basis,
                        num_gauss_points=gauss)
    if case == "const":
        routing = ThreadlikeRouting.linear(intercept=jnp.array([0.0, 0.0, 0.008]),
                                           slope=jnp.zeros(3))
    else:  # offset = intercept + slope * s, s = global arc length (m)
        routing = ThreadlikeRouting.linear(intercept=jnp.array([0.0, 0.0, 0.01]),
                                           slope=jnp.array([0.0, 0.0, (0.003 - 0.01) / L]))
    return sx.GVS.from_segments([seg], gravity=jnp.zeros(3),
                                base_pose=jnp.array([0, 0, 0, 1.0, 0, 0, 0]),
                                backend="jax",
                                actuators=ThreadlikeActuator.tendons(routing))


def static_tip(robot, nload=4, iters=40):
    res = lambda r, q, lam: r.elastic_force(q) - r.actuation_force(q, jnp.array([lam * TENSION]))
    q, residual = equilibrium(robot, res, nload, iters, 1e-14)
    tip = np.asarray(robot.forward_kinematics(q, jnp.array(L))[:3, 3])
    return tip, residual, q


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--case", choices=["const", "linear"], default="const")
    p.add_argument("--order", type=int, default=2)
    p.add_argument("--gauss", type=int, default=5)
    p.add_argument("--check", action="store_true",
                   help="also check actuation_matrix == -dl/dq by autodiff at the solution")
    a = p.parse_args()
    robot = build(a.order, a.gauss, a.case)
    tip, resid, q = static_tip(robot)
    np.set_printoptions(precision=17)
    print(f"soromox {sx.__version__} GVS 1 segment, Legendre order {a.order}, "
          f"{robot.num_coordinates} coordinates, {a.gauss} Gauss points, tendon case {a.case}, "
          f"T = {TENSION} N")
    print("tip =", repr(tip.tolist()))
    print(f"max|residual| = {resid:.3e}")
    if a.check:
        act = robot.actuators[0]
        dl = jax.jacfwd(lambda q_: act.path_lengths(robot, q_))(q)[0]
        A = robot.actuation_matrix(q)[:, 0]
        print(f"path length = {float(act.path_lengths(robot, q)[0]):.17g} m; "
              f"max|A + dl/dq| = {float(jnp.abs(A + dl).max()):.3e} "
              f"(max|A| = {float(jnp.abs(A).max()):.3e})")


if __name__ == "__main__":
    main()
