#!/usr/bin/env python3
"""soromox side of the peer comparison (docs/speed.md, "Against open peers"): a cantilever released under gravity.

gvsrom's scenario of the same problem is scripts/peers/gravity-release.toml; scripts/peers/run.sh
runs all three codes. `pip install soromox==0.5.0` (with jax, diffrax, equinox).

Problem: rod along world +x from the origin, L = 0.5 m, solid circle r = 0.01 m,
E = 1e7 Pa, nu = 0.5 (G = E/3), rho = 1000 kg/m^3, no damping, base clamped,
gravity 9.81 m/s^2 along -z, straight and at rest at t = 0, T = 1 s; output the
tip position at 100 Hz (101 samples).

soromox mapping (soromox 0.5.0, JAX backend, float64):
  --model pcs  soromox.PCS: piecewise-constant strain (Renda 2018), --segments
               equal links, each with all six strains [kx ky kz sx sy sz]
               (torsion, 2 bendings, stretch, 2 shears) -> 6N coordinates.
  --model gvs  soromox.GVS: --segments links joined by fixed joints, each with a
               Legendre strain basis of degree --order per strain (order 0 = PCS).
  --strains    six-character 0/1 mask of active strains (default 111111 = full
               Cosserat; e.g. 011100 drops torsion and shear).
  Links: LinkSpec.circular(young_modulus=E, shear_modulus=E/3, no damping;
  soromox rejects poisson_ratio=0.5, it requires -1 < nu < 0.5) ->
  K = diag(G*J, E*I, E*I, E*A, G*A, G*A) (no shear correction factor), mass
  density rho*diag(J, I, I, A, A, A) (rotational inertia included).  Clamp =
  fixed base_pose [qx qy qz qw x y z] = [0 0 0 1 0 0 0] (local x = world x);
  gravity = (0, 0, -9.81).  q = strain deviation from the straight reference,
  so y0 = 0 is the straight rod at rest.
  Integration: diffrax.diffeqsolve on robot.forward_dynamics (what
  DynamicalSystem.rollout_to does), --solver tsit5|dopri5|dopri8|kvaerno5 with a
  PIDController(--rtol, --atol), or a constant step --dt; --solver sie is
  soromox.SemiImplicitEuler (fixed --dt, via robot.rollout_to).
  --static also solves the static equilibrium (Newton with load continuation on
  robot.elastic_force + robot.gravitational_force; soromox has no statics solver).

Notes: all six strains are supported; soromox has no shear correction factor
(k = 1) and the strain is constant (PCS) or polynomial (GVS) per link, so the
tip converges ~O(h^2) in --segments for PCS and spectrally in --order for GVS.
The undamped axial/shear/torsion modes (omega_max ~1.1-1.2e4 rad/s at q = 0,
nearly independent of N) bound the explicit step to ~4-7e-5 s.  timing.json
also records num_steps, first_run_s and the max |total energy - E(0)| [J].

Timing: compile_s is jax lower+compile of the whole solve (incl. tip kinematics);
run_s is the median of --repeat timed executions.
"""
import argparse, json, math, pathlib, statistics, time

import jax

jax.config.update("jax_enable_x64", True)
import diffrax  # noqa: E402
import equinox as eqx  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
import soromox as sx  # noqa: E402
from soromox_statics import equilibrium  # noqa: E402

L, R, E, NU, RHO, GRAV, T, FS = 0.5, 0.01, 1e7, 0.5, 1000.0, 9.81, 1.0, 100


def build(a):
    mask = [c == "1" for c in a.strains]
    link = sx.LinkSpec.circular(length=L / a.segments, radius=R, density=RHO,
                                reference_strain=[float(v) for v in a.reference_strain.split(",")],
                                young_modulus=E, shear_modulus=E / (2 * (1 + NU)))
    kw = dict(gravity=jnp.array([0.0, 0.0, -GRAV]),
              base_pose=jnp.array([0, 0, 0, 1.0, 0, 0, 0]), backend="jax")
    if a.model == "pcs":
        st = sx.PCSStructure(num_gauss_points=a.gauss,
                             strain_selector=jnp.array(mask * a.segments))
        return sx.PCS.from_links([link] * a.segments, structure=st, **kw)
    basis = sx.StrainBasisSpec(type="legendre", strain_selector=[int(m) for m in mask],
                               basis_order=a.order)
    seg = sx.GVSSegment(link=link, joint=sx.JointSpec.fixed(), basis=basis,
                        num_gauss_points=max(a.gauss, 5))  # GVS needs >= 5
    return sx.GVS.from_segments([seg] * a.segments, **kw)


def solve(robot, a, ts):
    """Return (saved states (101, state_size), number of steps)."""
    y0 = jnp.zeros(robot.state_size)
    if a.solver == "sie":
        out = robot.rollout_to(sx.SystemState(t=jnp.array(0.0), y=y0), t1=T, solver_dt=a.dt,
                               save_ts=ts, solver=sx.SemiImplicitEuler(system=robot),
                               max_steps=math.ceil(T / a.dt) + 2)
        return out.y, jnp.array(math.ceil(T / a.dt))
    solver = {"tsit5": diffrax.Tsit5, "dopri5": diffrax.Dopri5, "dopri8": diffrax.Dopri8,
              "kvaerno5": diffrax.Kvaerno5}[a.solver]()
    ctrl = (diffrax.ConstantStepSize() if a.dt else
            diffrax.PIDController(rtol=a.rtol, atol=a.atol))
    sol = diffrax.diffeqsolve(diffrax.ODETerm(lambda t, y, r: r.forward_dynamics(t, y)),
                              solver, 0.0, T, a.dt or 1e-5, y0, args=robot,
                              saveat=diffrax.SaveAt(ts=ts), stepsize_controller=ctrl,
                              max_steps=a.max_steps)
    return sol.ys, sol.stats["num_steps"]


def tip(robot, q):
    return robot.forward_kinematics(q, jnp.array(L))[:3, 3]


def static_tip(robot, nload=10, iters=30):
    """Static equilibrium under gravity via Newton + load continuation."""
    res = lambda r, q, lam: r.elastic_force(q) + lam * r.gravitational_force(q)
    q, residual = equilibrium(robot, res, nload, iters, 1e-13)
    return np.asarray(tip(robot, q)), residual


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", required=True)
    p.add_argument("--model", choices=["pcs", "gvs"], default="pcs")
    p.add_argument("--segments", type=int, default=4)
    p.add_argument("--order", type=int, default=1, help="GVS Legendre degree")
    p.add_argument("--gauss", type=int, default=5, help="Gauss points per segment")
    p.add_argument("--strains", default="111111")
    p.add_argument("--solver", default="tsit5",
                   choices=["tsit5", "dopri5", "dopri8", "kvaerno5", "sie"])
    p.add_argument("--rtol", type=float, default=1e-6)
    p.add_argument("--atol", type=float, default=1e-8)
    p.add_argument("--dt", type=float, default=None, help="constant step (else adaptive)")
    p.add_argument("--max-steps", type=int, default=4_000_000)
    p.add_argument("--repeat", type=int, default=3, help="timed runs (0: use the first)")
    p.add_argument("--static", action="store_true")
    p.add_argument("--reference-strain", default="0,0,0,1,0,0",
                   help="the rod's rest strain [kx,ky,kz,sx,sy,sz] (default straight): e.g. "
                        "2,0,3,1,0,0 rests on a helix, and gravity then moves it in 3-D")
    a = p.parse_args()
    if a.solver == "sie" and not a.dt:
        p.error("--solver sie needs --dt")

    robot = build(a)
    ts = jnp.linspace(0.0, T, int(T * FS) + 1)
    nq = robot.num_coordinates

    def run(params, static):
        r = eqx.combine(params, static)
        ys, nsteps = solve(r, a, ts)
        return ys, jax.vmap(lambda y: tip(r, y[:nq]))(ys), nsteps

    params, static = eqx.partition(robot, eqx.is_array)
    t0 = time.perf_counter()
    fn = jax.jit(lambda prm: run(prm, static)).lower(params).compile()
    compile_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    ys, pos, nsteps = jax.block_until_ready(fn(params))
    first_s = time.perf_counter() - t0
    times = []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        ys, pos, nsteps = jax.block_until_ready(fn(params))
        times.append(time.perf_counter() - t0)

    energy = np.asarray(jax.vmap(lambda y: robot.total_energy(y[:nq], y[nq:2 * nq]))(ys))
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=False)  # never into an existing directory
    np.save(out / "t.npy", np.asarray(ts))
    np.save(out / "tip_position.npy", np.asarray(pos))
    info = {
        "compile_s": compile_s, "first_run_s": first_s,
        "run_s": statistics.median(times) if times else first_s, "run_s_all": times,
        "settings": {k: v for k, v in vars(a).items() if k != "out"}
        | {"num_coordinates": nq, "num_steps": int(nsteps), "backend": "jax-cpu-f64"},
        "summary": (f"{a.model.upper()}, {a.segments} segment(s)"
                    + (f", Legendre order {a.order}" if a.model == "gvs" else "")
                    + f", {nq} coordinates, {a.solver}"
                    + (f" dt {a.dt}" if a.dt else f" rtol {a.rtol}")
                    + f", {int(nsteps)} steps"),
        "energy_drift_abs": float(np.abs(energy - energy[0]).max()),
        "soromox_version": sx.__version__, "jax_version": jax.__version__,
    }
    if a.static:
        info["static_tip"], info["static_residual"] = static_tip(robot)
        info["static_tip"] = info["static_tip"].tolist()
    (out / "timing.json").write_text(json.dumps(info, indent=1) + "\n")
    print(json.dumps({k: info[k] for k in ("compile_s", "run_s")} | {
        "tip_t0": pos[0].tolist(), "tip_t0.5": pos[50].tolist(), "tip_t1": pos[-1].tolist(),
        "max_abs_y": float(jnp.abs(pos[:, 1]).max()), "num_steps": int(nsteps),
        "static_tip": info.get("static_tip")}))


if __name__ == "__main__":
    main()
