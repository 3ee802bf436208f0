"""The paper's symbols in a sentence each, for the controls' help (hover) and the page's
"about" section: what a reader without the paper needs to read a control."""

from __future__ import annotations

#: The labels of the algorithms' parameters' controls, in the verdict's symbols (the registry's
#: names are keys: "damping_threshold"). The paper's parameters are labelled by their names.
PARAMETER_LABELS = {
    "damping": "λ (damping)",
    "damping_threshold": "damping threshold (σ_min)",
    "gain": "k (null-space gain)",
}

#: The paper's symbols, as the controls and panels use them.
SYMBOLS = {
    "gamma": "γ: the decay rate of the task error, e(θ) = e(0) exp(−γθ), eq. (5); in discrete "
    "mode the step of x ← x − γ J# e, which converges only for 0 < γ < 2",
    "a": "a: the parameter of the map's family (Manipulator 1: eq. (36); unicycle: the "
    "homotopy of eq. (45))",
    "b": "b: the second integration constant of the E2-optimal map (36)",
    "C1": "C1, C2: the integration constants of the E1-optimal map (32); h is singular where "
    "its gradient vanishes",
    "C2": "C1, C2: the integration constants of the E1-optimal map (32); h is singular where "
    "its gradient vanishes",
    "h": "h: the augmenting map, eq. (9): the extended Jacobian adds the equation "
    "h(x) = h(x0) to the task",
    "l": "l: the arm length of Manipulator 2 [m]",
    "T": "T: the control horizon of the unicycle [s]",
    "q0": "q0: the unicycle's initial pose (q1, q2 [m], q3 [rad]); A and B are the paper's",
    "rest": "x_rest: the rest configuration of the posture inverse J^P# dy + (I − J^P# J) "
    "k (x_rest − x) ‖dy‖ (Liégeois 1977): inside the self-motion the joints are pulled toward it "
    "at gain k",
    "x0": "x0: the start configuration (for the unicycle, the control parameters lambda10, "
    "lambda11, lambda20, lambda21 of eq. (41): u1 = lambda10 + lambda11 sin t, u2 = lambda20 "
    "+ lambda21 sin t)",
}
