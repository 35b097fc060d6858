"""Newton with load continuation on a soromox residual (soromox has no statics solver): shared by
soromox_release.py (gravity) and soromox_tendon.py (a tendon's pull)."""
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np


def equilibrium(robot, res, nload, iters, tol):
    """q with res(robot, q, 1) = 0, reached through the load factors 1/nload, 2/nload, ..., 1;
    Newton steps with the Jacobian by jax.jacfwd until the step is below tol. Returns q and the
    largest residual component at the full load."""
    step = eqx.filter_jit(lambda r, q, lam: q - jnp.linalg.solve(
        jax.jacfwd(res, argnums=1)(r, q, lam), res(r, q, lam)))
    q = jnp.zeros(robot.num_coordinates)
    for lam in np.linspace(1.0 / nload, 1.0, nload):
        for _ in range(iters):
            q, q_old = step(robot, q, lam), q
            if float(jnp.abs(q - q_old).max()) < tol:
                break
    return q, float(jnp.abs(res(robot, q, 1.0)).max())
