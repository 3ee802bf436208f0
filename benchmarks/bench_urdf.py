"""URDF arms: jik's kinematics against Pinocchio's, in the same run, on the Franka Panda.

The task is the full pose ("pose": x y z rx ry rz, the rotation vector of R0^T R), so both sides
compute the same k(x) (6,) and J(x) (6, 7):

- jik: ``UrdfChain.forward_jacobian`` (engine/serial_chain.py, engine/pose_task.py).
- Pinocchio: ``computeJointJacobians``, ``updateFramePlacements``, ``getFrameJacobian`` (LOCAL)
  and ``log3``/``Jlog3`` of R0^T R: k = (p, log3), J = (R Jv_local, Jlog3 Jw_local). "Pinocchio
  SE(3)" is the first three calls alone (the frame's pose and its 6 x 7 Jacobian, no log).

1. One configuration, k and J.
2. A batch of 4096 configurations: jik's one batched call against a Python loop over Pinocchio.
3. One pose leg of the paper's continuous algorithm (7), pseudoinverse, to task error 1e-10:
   ``engine.solver.solve`` against ``solve_ivp`` (RK45 and DOP853, rtol = atol = 1e-12, a
   terminal event at the error) on Pinocchio's k and J.

Times are wall-clock (``time.perf_counter``): for one configuration the best of 40 rounds in
which jik and Pinocchio take turns, otherwise medians. The machine may be shared: compare the
ratios of one run.
"""

from __future__ import annotations

import time
from typing import cast

import numpy as np
from scipy.integrate import solve_ivp

from ..engine.arms import ARMS
from ..engine.dop853 import ATOL, RTOL
from ..engine.inverses import Pseudoinverse
from ..engine.robot_spec import robot_from_dict
from ..engine.solver import solve
from ..engine.urdf import UrdfChain
from .bench_solver import median_time

TOL = 1e-10
#: The leg: from home, 8 cm along x and 8 cm along y, a turn of 0.2 rad about z and 0.15 about x.
MOVE = np.array([0.08, 0.08, 0.0, 0.15, 0.0, 0.2])


def _interleaved(fns: dict, calls: int, repeat: int) -> dict:
    """Each function's time per call, the best of ``repeat`` rounds of ``calls`` calls, the
    functions taking turns in every round (a shared machine's load then weighs on all alike)."""
    best = dict.fromkeys(fns, float("inf"))
    for _ in range(repeat):
        for name, fn in fns.items():
            t = time.perf_counter()
            for _ in range(calls):
                fn()
            best[name] = min(best[name], (time.perf_counter() - t) / calls)
    return best


class PinocchioPose:
    """The same pose task's k and J from Pinocchio (see the module notes)."""

    def __init__(self, pin, urdf: str, end_link: str, reference: np.ndarray) -> None:
        self.pin, self.model = pin, pin.buildModelFromXML(urdf)
        self.data, self.frame = self.model.createData(), self.model.getFrameId(end_link)
        self.R0T = reference.T

    def se3(self, q):
        pin = self.pin
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        return self.data.oMf[self.frame], pin.getFrameJacobian(
            self.model, self.data, self.frame, pin.LOCAL
        )

    def forward_jacobian(self, q):
        M, J6 = self.se3(q)
        R = M.rotation
        Rrel = self.R0T @ R
        k = np.concatenate([M.translation, self.pin.log3(Rrel)])
        return k, np.vstack([R @ J6[:3], self.pin.Jlog3(Rrel) @ J6[3:]])


def _pinocchio_leg(pose: PinocchioPose, x0, y_d, method: str):
    def f(_t, x):
        k, J = pose.forward_jacobian(x)
        return -J.T @ np.linalg.solve(J @ J.T, k - y_d)

    def reached(_t, x):
        return np.linalg.norm(pose.forward_jacobian(x)[0] - y_d) - TOL

    reached.terminal = True  # type: ignore[attr-defined]  # solve_ivp reads event attributes off the function
    sol = solve_ivp(f, (0, 200), x0, method=method, rtol=RTOL, atol=ATOL, events=reached)
    return sol.y[:, -1], sol.nfev


def run(quick: bool = False) -> dict | None:
    try:
        import pinocchio as pin
    except ImportError:  # Pinocchio is a test dependency (pip install pin)
        print("bench urdf needs Pinocchio: pip install pin")
        return None
    arm = ARMS["panda"]
    kin = cast(UrdfChain, robot_from_dict({"name": "panda", "task": "pose"}).kinematics)
    pose = PinocchioPose(pin, arm.urdf, arm.end_link, kin.reference)
    x = np.array(arm.home) + 0.1
    k, J = kin.forward_jacobian(x)
    kp, Jp = pose.forward_jacobian(x)
    agree = max(np.abs(k - kp).max(), np.abs(J - Jp).max())
    reps, calls = (5, 100) if quick else (40, 200)
    one = _interleaved(
        {
            "jik": lambda: kin.forward_jacobian(x),
            "pinocchio": lambda: pose.forward_jacobian(x),
            "pinocchio_se3": lambda: pose.se3(x),
        },
        calls,
        reps,
    )
    reps = 3 if quick else 9
    X = np.array(arm.home) + np.random.default_rng(8).uniform(-0.5, 0.5, (4096, 7))
    loop_n = 512 if quick else 4096
    batch = {
        "jik": median_time(lambda: kin.forward_jacobian(X), reps) / len(X),
        "pinocchio_loop": median_time(lambda: [pose.forward_jacobian(q) for q in X[:loop_n]], 3)
        / loop_n,
    }
    x0 = np.array(arm.home)
    y_d = kin.forward(x0) + MOVE
    inverse = Pseudoinverse(kin)
    res = solve(inverse, x0, y_d, tol=TOL, record=False)
    leg = {"jik": median_time(lambda: solve(inverse, x0, y_d, tol=TOL, record=False), reps)}
    ends = {"jik": res.x}
    for method in ("RK45", "DOP853"):
        leg[f"solve_ivp_{method}"] = median_time(
            lambda m=method: _pinocchio_leg(pose, x0, y_d, m), 3
        )
        ends[method], _ = _pinocchio_leg(pose, x0, y_d, method)
    return {
        "agree": agree,
        "one": one,
        "batch": batch,
        "leg": leg,
        "success": res.success,
        "leg_gap": max(np.abs(ends["jik"] - e).max() for e in ends.values()),
    }


def main(quick: bool = False) -> None:
    r = run(quick=quick)
    if r is None:
        return
    one, batch, leg = r["one"], r["batch"], r["leg"]
    print(f"Franka Panda, pose task (6 x 7): jik and Pinocchio agree to {r['agree']:.1e}")
    print("one configuration, k and J:")
    print(f"  jik                      {one['jik'] * 1e6:8.1f} us")
    print(
        f"  Pinocchio (same k, J)    {one['pinocchio'] * 1e6:8.1f} us   "
        f"jik / Pinocchio = {one['jik'] / one['pinocchio']:.2f}"
    )
    print(
        f"  Pinocchio SE(3) only     {one['pinocchio_se3'] * 1e6:8.1f} us   "
        f"jik / that = {one['jik'] / one['pinocchio_se3']:.2f}"
    )
    print("4096 configurations, per configuration:")
    print(f"  jik, one batched call    {batch['jik'] * 1e6:8.2f} us")
    print(
        f"  Pinocchio, Python loop   {batch['pinocchio_loop'] * 1e6:8.2f} us   "
        f"loop / jik = {batch['pinocchio_loop'] / batch['jik']:.1f}"
    )
    print(
        f"one pose leg of (7), pseudoinverse, to error {TOL:g} "
        f"(ends agree to {r['leg_gap']:.1e}; jik converged: {r['success']}):"
    )
    print(f"  jik solve                {leg['jik'] * 1e3:8.2f} ms")
    for method in ("RK45", "DOP853"):
        t = leg[f"solve_ivp_{method}"]
        print(
            f"  solve_ivp {method:6s} + Pin. {t * 1e3:8.2f} ms   that / jik = {t / leg['jik']:.1f}"
        )
