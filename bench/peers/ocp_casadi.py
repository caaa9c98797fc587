#!/usr/bin/env python3
"""Reference solver for paper 002's optimal-control problem (DMOC, §2.3) with CasADi + IPOPT.

The transcription (n joints, N steps), as crates/cellplan-ocp/src/dmoc.rs writes the equations:

- Variables, in this order in the NLP vector: q_0 ... q_N (n each), u_{1/2} ... u_{N-1/2} (n each,
  the torques at the step midpoints), h (the step), qd_0, qd_N (n each).
  Count (2N + 3) n + 1.
- Lagrangian L(q, v) = 1/2 v^T M(q) v - V(q): M by Pinocchio's crba (upper triangle mirrored),
  V by Pinocchio's computePotentialEnergy, gravity (0, 0, -9.81) in the URDF root frame, both on
  CasADi's SX scalar. dL/dq and dL/dv by casadi.gradient of that expression.
  Discrete Lagrangian L_d(a, b) = h L((a+b)/2, (b-a)/h); with m = (a+b)/2, v = (b-a)/h:
  D1 L_d(a, b) = h/2 dL/dq(m, v) - dL/dv(m, v), D2 L_d(a, b) = h/2 dL/dq(m, v) + dL/dv(m, v).
- Equality constraints, in this order ((N+1) n rows):
  start   dL/dv(q_0, qd_0) + D1 L_d(q_0, q_1) + h/2 u_{1/2} = 0
  k=1..N-1 D2 L_d(q_{k-1}, q_k) + D1 L_d(q_k, q_{k+1}) + h/2 (u_{k-1/2} + u_{k+1/2}) = 0
  end     -dL/dv(q_N, qd_N) + D2 L_d(q_{N-1}, q_N) + h/2 u_{N-1/2} = 0
- Velocity limits as linear inequalities (2 N n rows, after the equalities): for i = 0..N-1,
  first all (q_{i+1} - q_i) - h v_max <= 0 (i-major, joint-minor), then all
  (q_{i+1} - q_i) + h v_max >= 0.
- Variable bounds: q_0 = q_start, q_N = q_goal, qd_0 = qd_N = 0 (fixed: lower = upper; IPOPT
  removes fixed variables, `fixed_variable_treatment` make_parameter); joint limits on q_1..q_{N-1};
  |u_{i+1/2},j| <= u_max,j; h_min <= h <= h_max.
- Cost J = sum_{i=0}^{N-1} h (c_t + c_e |u_{i+1/2}|^2 + c_v |(q_{i+1} - q_i)/h|^2)
         = N h c_t + h c_e sum |u|^2 + c_v sum |q_{i+1} - q_i|^2 / h.
- Initial guess: q linear from q_start to q_goal; u_{i+1/2} = the gravity torques dV/dq at the
  guess's midpoint (q_i + q_{i+1})/2; h = 1.5 max_j |q_goal,j - q_start,j| / v_max,j / N (clamped
  into [h_min, h_max]; h_max if the start is the goal); qd_0 = qd_N = 0.

How M and V get onto CasADi's scalar: `import pinocchio.casadi as cpin` (cpin.crba,
cpin.computePotentialEnergy on cpin.Model(model)) when that module exists; it does not in the PyPI
`pin` wheels (built without CasADi; pinocchio issues #2578, #2759), so otherwise the script runs
ocp_pin_casadi/pin_casadi_mv, a 60-line C++ program that instantiates the same Pinocchio
templates (ModelTpl<casadi::SX>, crba, computePotentialEnergy) from the headers the `pin` wheel
ships and saves the result as a casadi.Function (built on first use by ocp_pin_casadi/build.sh,
~1.5 min). Either way the script checks, before solving, M, V and the kinetic energy against
Pinocchio's double-precision crba / computePotentialEnergy / computeKineticEnergy at random states,
and dL/dq against central differences of Pinocchio's numeric Lagrangian.

The Pinocchio model is built as bench/peers/dynamics_pin.py builds it (same code): the URDF pruned
to the movable joints on root -> tip, pin.buildModelFromXML with no root joint; links on fixed
joints are lumped into their movable ancestor's body, links fixed to the root into the universe.

Problem file (JSON): {"urdf": path (relative to the repo root or absolute), "packages":
{"name": path} (only used to report whether the URDF's package:// meshes resolve: dynamics need
no meshes), "tip": "tool0", "q_start", "q_goal", "N", "v_max" (optional, default the URDF's
velocity limits), "u_max" (optional, default the URDF's effort limits; required where the URDF
gives effort 0), "h_min", "h_max", "weights": {"c_t", "c_e", "c_v"} (defaults 1, 1e-6, 1)}.

IPOPT (bundled with CasADi): tol 1e-10, print_level 0, exact Hessian, max_iter 3000,
bound_relax_factor 0 (bounds hold exactly at the solution), the rest at IPOPT's defaults; the MX
graph is expanded to SX before solving.

Usage:
  ocp_casadi.py PROBLEM.json [--json OUT] [--tol 1e-10] [--max-iter 3000] [--print-level 0]
                [--bound-relax-factor 0] [--backend auto|cpin|helper] [--no-expand]
                [--guess-u gravity|zero] [--guess-h-factor F] [--guess-seed S [--guess-noise 0.3]]
  ocp_casadi.py PROBLEM.json --check SOLUTION.json [--json OUT]
A solution file has {"q": [[...] x (N+1)], "u": [[...] x N], "h", "qd0", "qdN"}, at the top
level or under "solution" (as --json writes it). --check evaluates this script's equations,
bounds and cost at it (no solve).
"""
import argparse
import glob
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import numpy as np
import casadi as ca
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
from dynamics_pin import prune, MOVABLE  # noqa: E402  (the same pruning as the dynamics reference)

GRAVITY = np.array([0.0, 0.0, -9.81])
HELPER_DIR = os.path.join(HERE, "ocp_pin_casadi")
HELPER_SRC = os.path.join(HELPER_DIR, "pin_casadi_mv.cpp")
HELPER_BIN = os.path.join(HELPER_DIR, "build", "pin_casadi_mv")
DEFAULT_WEIGHTS = {"c_t": 1.0, "c_e": 1e-6, "c_v": 1.0}
ACTIVE_REL = 1e-6  # a bound counts as active within this fraction of its value


def repo_path(p):
    return p if os.path.isabs(p) else os.path.join(REPO, p)


def ipopt_version():
    libs = glob.glob(os.path.join(os.path.dirname(ca.__file__), "libipopt.so.*.*.*"))
    m = re.search(r"libipopt\.so\.(\d+\.\d+\.\d+)$", libs[0]) if libs else None
    return m.group(1) if m else "unknown"


# ---------------------------------------------------------------------------------------------
# The robot


class Robot:
    """The Pinocchio model of the root -> tip chain and the CasADi functions of its Lagrangian."""

    def __init__(self, prob, backend="auto"):
        self.urdf = repo_path(prob["urdf"])
        tree = ET.parse(self.urdf)
        xml = tree.getroot()
        self.package_report = resolve_packages(xml, prob.get("packages", {}))
        self.root_link, path, self.pruned = prune(xml, prob.get("tip", "tool0"))
        chain = [j for j in path if j.get("type") in MOVABLE]
        for j in chain:
            if j.get("type") not in ("revolute", "prismatic"):
                sys.exit(f"joint {j.get('name')}: type {j.get('type')} not supported")
            if j.find("mimic") is not None:
                sys.exit(f"joint {j.get('name')} is a mimic joint: not supported")
        self.model = pin.buildModelFromXML(ET.tostring(xml, encoding="unicode"))
        self.model.gravity = pin.Motion(GRAVITY, np.zeros(3))
        self.data = self.model.createData()
        self.joints = list(self.model.names)[1:]
        if self.joints != [j.get("name") for j in chain]:
            sys.exit(f"Pinocchio's joints {self.joints} are not the chain's {[j.get('name') for j in chain]}")
        n = self.n = self.model.nv
        if self.model.nq != n:
            sys.exit("nq != nv")
        lim = [j.find("limit") for j in chain]
        self.lower = np.array([float(l.get("lower")) for l in lim])
        self.upper = np.array([float(l.get("upper")) for l in lim])
        self.urdf_vmax = np.array([float(l.get("velocity", "0")) for l in lim])
        self.urdf_effort = np.array([float(l.get("effort", "0")) for l in lim])
        self.bodies = [{"joint": self.model.names[i], "mass": self.model.inertias[i].mass}
                       for i in range(1, self.model.njoints)]
        self.universe_mass = self.model.inertias[0].mass

        self.backend = self._mv_function(backend)
        q, v = ca.SX.sym("q", n), ca.SX.sym("v", n)
        M, V, T = self.MV(q, v)
        L = 0.5 * ca.mtimes([v.T, M, v]) - V
        Lq, Lv = ca.gradient(L, q), ca.gradient(L, v)
        self.dL = ca.Function("dL", [q, v], [Lq, Lv], ["q", "v"], ["dLdq", "dLdv"])
        self.Lfun = ca.Function("L", [q, v], [L])
        self.grav = ca.Function("grav", [q], [ca.gradient(V, q)])
        a, b, h = ca.SX.sym("a", n), ca.SX.sym("b", n), ca.SX.sym("h")
        lq, lv = self.dL((a + b) / 2, (b - a) / h)
        self.slot = ca.Function("slot", [a, b, h], [h / 2 * lq - lv, h / 2 * lq + lv],
                                ["a", "b", "h"], ["D1", "D2"])
        self.self_check = self._self_check()

    def _mv_function(self, backend):
        n = self.n
        if backend in ("auto", "cpin"):
            try:
                import pinocchio.casadi as cpin
            except ImportError:
                if backend == "cpin":
                    sys.exit("pinocchio.casadi is not importable (PyPI `pin` has no CasADi support)")
            else:
                cmodel = cpin.Model(self.model)  # the cast keeps the gravity set above
                cdata = cmodel.createData()
                q, v = ca.SX.sym("q", n), ca.SX.sym("v", n)
                M = cpin.crba(cmodel, cdata, q)
                M = ca.triu(M) + ca.triu(M, False).T
                V = cpin.computePotentialEnergy(cmodel, cdata, q)
                cpin.forwardKinematics(cmodel, cdata, q, v)
                T = cpin.computeKineticEnergy(cmodel, cdata)
                self.MV = ca.Function("pin_MV", [q, v], [M, V, T], ["q", "v"], ["M", "V", "T"])
                return "pinocchio.casadi (cpin)"
        if not os.path.exists(HELPER_BIN) or os.path.getmtime(HELPER_BIN) < os.path.getmtime(HELPER_SRC):
            print("building ocp_pin_casadi/build/pin_casadi_mv (once, ~1.5 min) ...", file=sys.stderr)
            subprocess.run(["bash", os.path.join(HELPER_DIR, "build.sh")], check=True, stdout=sys.stderr,
                           env=dict(os.environ, PYTHON=sys.executable))
        with tempfile.TemporaryDirectory() as tmp:
            mtxt, fout = os.path.join(tmp, "model.txt"), os.path.join(tmp, "mv.casadi")
            self.model.saveToText(mtxt)
            r = subprocess.run([HELPER_BIN, mtxt, fout], capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"pin_casadi_mv failed: {r.stderr}")
            self.MV = ca.Function.load(fout)
        return "ocp_pin_casadi/pin_casadi_mv (Pinocchio crba/computePotentialEnergy on casadi::SX, C++)"

    def _self_check(self, count=20, seed=7):
        """M, V, T against Pinocchio in double; dL/dq against central differences of Pinocchio's L."""
        rng = np.random.default_rng(seed)
        m, d = self.model, self.data
        worst = {"M_rel": 0.0, "V_abs": 0.0, "T_rel": 0.0, "dLdq_rel_fd": 0.0, "dLdv_rel": 0.0}

        def L_pin(q, v):
            M = pin.crba(m, d, q)
            M = np.triu(M) + np.triu(M, 1).T
            return 0.5 * v @ M @ v - pin.computePotentialEnergy(m, d, q)

        for _ in range(count):
            q = rng.uniform(self.lower, self.upper)
            v = rng.uniform(-2.0, 2.0, self.n)
            M, V, T = (np.array(x) for x in self.MV(q, v))
            V, T = V.item(), T.item()
            Mp = pin.crba(m, d, q)
            Mp = np.triu(Mp) + np.triu(Mp, 1).T
            Vp = pin.computePotentialEnergy(m, d, q)
            pin.forwardKinematics(m, d, q, v)
            Tp = pin.computeKineticEnergy(m, d)
            worst["M_rel"] = max(worst["M_rel"], np.abs(M - Mp).max() / np.abs(Mp).max())
            worst["V_abs"] = max(worst["V_abs"], abs(V - Vp))
            worst["T_rel"] = max(worst["T_rel"], abs(T - Tp) / max(abs(Tp), 1e-300))
            lq, lv = (np.array(x).ravel() for x in self.dL(q, v))
            worst["dLdv_rel"] = max(worst["dLdv_rel"], np.abs(lv - Mp @ v).max() / np.abs(Mp @ v).max())
            eps = 1e-6
            fd = np.array([(L_pin(q + eps * e, v) - L_pin(q - eps * e, v)) / (2 * eps) for e in np.eye(self.n)])
            worst["dLdq_rel_fd"] = max(worst["dLdq_rel_fd"], np.abs(lq - fd).max() / max(np.abs(fd).max(), 1.0))
        ok = worst["M_rel"] < 1e-12 and worst["T_rel"] < 1e-12 and worst["dLdv_rel"] < 1e-12 \
            and worst["V_abs"] < 1e-9 * max(1.0, self.universe_mass + sum(b["mass"] for b in self.bodies)) \
            and worst["dLdq_rel_fd"] < 1e-6
        if not ok:
            sys.exit(f"self-check against Pinocchio failed: {worst}")
        worst["states"] = count
        worst["note"] = ("max over random states (q uniform in the joint limits, v in +-2): CasADi M, V, T vs "
                         "pin.crba/computePotentialEnergy/computeKineticEnergy in double; dL/dv vs M v; "
                         "dL/dq vs central differences (step 1e-6) of Pinocchio's numeric L")
        return worst


def resolve_packages(xml, packages):
    """How many package:// mesh URIs resolve through `packages` (information only)."""
    total, found, missing_pkgs = 0, 0, set()
    for mesh in xml.iter("mesh"):
        fn = mesh.get("filename", "")
        if not fn.startswith("package://"):
            continue
        total += 1
        pkg, _, rest = fn[len("package://"):].partition("/")
        if pkg not in packages:
            missing_pkgs.add(pkg)
            continue
        if os.path.exists(os.path.join(repo_path(packages[pkg]), rest)):
            found += 1
    return {"mesh_uris": total, "resolved_files": found, "unknown_packages": sorted(missing_pkgs),
            "note": "meshes are not used by the dynamics; visual .dae files are not in the repo on purpose"}


# ---------------------------------------------------------------------------------------------
# The problem


class Problem:
    def __init__(self, prob, robot):
        self.robot, n = robot, robot.n
        self.N = N = int(prob["N"])
        self.q_start = np.array(prob["q_start"], float)
        self.q_goal = np.array(prob["q_goal"], float)
        for name, q in (("q_start", self.q_start), ("q_goal", self.q_goal)):
            if q.shape != (n,):
                sys.exit(f"{name} has {q.size} values, the chain {n} joints")
            if np.any(q < robot.lower) or np.any(q > robot.upper):
                sys.exit(f"{name} is outside the joint limits")
        if "v_max" in prob:
            self.v_max, self.v_src = np.array(prob["v_max"], float), "problem file"
        else:
            self.v_max, self.v_src = robot.urdf_vmax, "URDF <limit velocity>"
        if "u_max" in prob:
            self.u_max, self.u_src = np.array(prob["u_max"], float), "problem file"
        else:
            self.u_max, self.u_src = robot.urdf_effort, "URDF <limit effort>"
        if np.any(~(self.v_max > 0)) or np.any(~np.isfinite(self.v_max)):
            sys.exit(f"v_max {self.v_max} ({self.v_src}): every joint needs a finite positive limit")
        if np.any(~(self.u_max > 0)) or np.any(~np.isfinite(self.u_max)):
            sys.exit(f"u_max {self.u_max} ({self.u_src}): every joint needs a finite positive limit "
                     "(give \"u_max\" in the problem file where the URDF's effort is 0)")
        self.h_min, self.h_max = float(prob.get("h_min", 0.001)), float(prob.get("h_max", 1.0))
        w = dict(DEFAULT_WEIGHTS)
        w.update(prob.get("weights", {}))
        self.w = w
        self.n_var = (2 * N + 3) * n + 1
        self.n_eq = (N + 1) * n
        self.n_ineq = 2 * N * n

    # layout
    def split(self, w):
        n, N = self.robot.n, self.N
        Q = ca.reshape(w[: (N + 1) * n], n, N + 1)
        o = (N + 1) * n
        U = ca.reshape(w[o: o + N * n], n, N)
        o += N * n
        h = w[o]
        qd0, qdN = w[o + 1: o + 1 + n], w[o + 1 + n: o + 1 + 2 * n]
        return Q, U, h, qd0, qdN

    def pack(self, Q, U, h, qd0, qdN):
        return np.concatenate([np.asarray(Q, float).T.ravel(), np.asarray(U, float).T.ravel(),
                               [float(h)], np.ravel(qd0), np.ravel(qdN)])

    def expressions(self, w):
        """(dynamics residual rows as a list of (kind, k, expr), velocity rows (upper, lower), J, J parts)."""
        r, N = self.robot, self.N
        Q, U, h, qd0, qdN = self.split(w)
        D1, D2 = [], []
        for i in range(N):
            d1, d2 = r.slot(Q[:, i], Q[:, i + 1], h)
            D1.append(d1)
            D2.append(d2)
        dyn = [("start", 0, r.dL(Q[:, 0], qd0)[1] + D1[0] + h / 2 * U[:, 0])]
        for k in range(1, N):
            dyn.append(("interior", k, D2[k - 1] + D1[k] + h / 2 * (U[:, k - 1] + U[:, k])))
        dyn.append(("end", N, -r.dL(Q[:, N], qdN)[1] + D2[N - 1] + h / 2 * U[:, N - 1]))
        dQ = Q[:, 1:] - Q[:, :-1]
        vmax = ca.DM(self.v_max)
        up = ca.vertcat(*[dQ[:, i] - h * vmax for i in range(N)])
        lo = ca.vertcat(*[dQ[:, i] + h * vmax for i in range(N)])
        c = self.w
        J_t = N * h * c["c_t"]
        J_e = h * c["c_e"] * ca.sumsqr(U)
        J_v = c["c_v"] * ca.sumsqr(dQ) / h
        return dyn, up, lo, J_t + J_e + J_v, (J_t, J_e, J_v)

    def bounds(self):
        n, N = self.robot.n, self.N
        inf = np.inf
        lq = np.tile(self.robot.lower, (N + 1, 1))
        uq = np.tile(self.robot.upper, (N + 1, 1))
        lq[0] = uq[0] = self.q_start
        lq[N] = uq[N] = self.q_goal
        lbx = np.concatenate([lq.ravel(), np.tile(-self.u_max, N), [self.h_min], np.zeros(2 * n)])
        ubx = np.concatenate([uq.ravel(), np.tile(self.u_max, N), [self.h_max], np.zeros(2 * n)])
        lbg = np.concatenate([np.zeros(self.n_eq), np.full(N * n, -inf), np.zeros(N * n)])
        ubg = np.concatenate([np.zeros(self.n_eq), np.zeros(N * n), np.full(N * n, inf)])
        return lbx, ubx, lbg, ubg

    def initial_guess(self, h_factor=1.0, u_mode="gravity", seed=None, noise=0.3):
        N = self.N
        s = np.linspace(0.0, 1.0, N + 1)
        Q = self.q_start[:, None] + (self.q_goal - self.q_start)[:, None] * s[None, :]
        if seed is not None:
            # a smooth random detour: noise * sin(pi s) * (uniform in +-1 per joint), inside the limits
            amp = np.random.default_rng(seed).uniform(-1.0, 1.0, self.robot.n)
            Q = Q + noise * amp[:, None] * np.sin(np.pi * s)[None, :]
            Q = np.clip(Q, self.robot.lower[:, None], self.robot.upper[:, None])
        U = np.column_stack([np.array(self.robot.grav((Q[:, i] + Q[:, i + 1]) / 2)).ravel() for i in range(N)])
        U = np.clip(U, -self.u_max[:, None], self.u_max[:, None])
        if u_mode == "zero":
            U = np.zeros_like(U)
        t_slow = float(np.max(np.abs(self.q_goal - self.q_start) / self.v_max))
        h = 1.5 * t_slow / N * h_factor if t_slow > 0 else self.h_max
        h = min(max(h, self.h_min), self.h_max)
        z = np.zeros(self.robot.n)
        return self.pack(Q, U, h, z, z), {"h": h, "t_slowest_joint": t_slow, "h_factor": h_factor, "u": u_mode,
                                          "q_detour_seed": seed, "q_detour_amplitude": noise if seed is not None else 0.0}


# ---------------------------------------------------------------------------------------------
# Evaluation of a solution (shared by the solve and --check)


def evaluate(P, x):
    """Residuals, bound violations and activity, and the cost at the NLP vector x (numeric)."""
    n, N = P.robot.n, P.N
    w = ca.SX.sym("w", P.n_var)
    dyn, up, lo, J, parts = P.expressions(w)
    f = ca.Function("ev", [w], [ca.vertcat(*[e for _, _, e in dyn]), up, lo, J, *parts])
    # the size of the terms in each row (for a relative residual): |D2| + |D1| + |h/2 u| summed
    Q, U, h, qd0, qdN = P.split(w)
    r = P.robot
    terms = []
    for kind, k, _ in dyn:
        t = 0
        if kind == "start":
            t = ca.fabs(r.dL(Q[:, 0], qd0)[1]) + ca.fabs(r.slot(Q[:, 0], Q[:, 1], h)[0]) + ca.fabs(h / 2 * U[:, 0])
        elif kind == "end":
            t = ca.fabs(r.dL(Q[:, N], qdN)[1]) + ca.fabs(r.slot(Q[:, N - 1], Q[:, N], h)[1]) + ca.fabs(h / 2 * U[:, N - 1])
        else:
            t = ca.fabs(r.slot(Q[:, k - 1], Q[:, k], h)[1]) + ca.fabs(r.slot(Q[:, k], Q[:, k + 1], h)[0]) \
                + ca.fabs(h / 2 * (U[:, k - 1] + U[:, k]))
        terms.append(t)
    ft = ca.Function("terms", [w], [ca.vertcat(*terms)])
    g, gu, gl, Jv, Jt, Je, Jvel = (np.array(v).ravel() for v in f(x))
    scale = np.array(ft(x)).ravel()
    res = g.reshape(N + 1, n)
    sc = scale.reshape(N + 1, n)
    Qn, Un, hn, qd0n, qdNn = (np.array(v, float) for v in P.split(ca.DM(x)))
    hn = hn.item()
    Qn = Qn.reshape(n, N + 1)
    Un = Un.reshape(n, N)
    dQ = np.diff(Qn, axis=1)
    vel = np.abs(dQ) / hn
    rel = np.abs(res) / np.maximum(sc, 1e-300)
    rn = residual_numeric(P.robot, Qn, Un, hn, np.ravel(qd0n), np.ravel(qdNn))
    out = {
        "dynamics_residual": {
            "max_abs": float(np.abs(res).max()),
            "max_abs_start": float(np.abs(res[0]).max()),
            "max_abs_interior": float(np.abs(res[1:N]).max()) if N > 1 else 0.0,
            "max_abs_end": float(np.abs(res[N]).max()),
            "max_rel": float(rel.max()),
            "where_max_abs": {"row": int(np.argmax(np.abs(res).max(1))), "joint": int(np.argmax(np.abs(res).max(0)))},
            "note": ("rows 0 = start, 1..N-1 = interior k, N = end (N·m·s); max_rel divides each entry by "
                     "the sum of the absolute values of its terms (|dL/dv| or |D2|, |D1|, |h/2 u|)"),
        },
        "bound_violation": {
            "joint_limits": float(max(0.0, np.max(P.robot.lower[:, None] - Qn), np.max(Qn - P.robot.upper[:, None]))),
            "boundary_q_start": float(np.abs(Qn[:, 0] - P.q_start).max()),
            "boundary_q_goal": float(np.abs(Qn[:, N] - P.q_goal).max()),
            "boundary_qd0": float(np.abs(qd0n).max()),
            "boundary_qdN": float(np.abs(qdNn).max()),
            "velocity_rows": float(max(0.0, gu.max(), -gl.min())),
            "torque": float(max(0.0, np.max(np.abs(Un) - P.u_max[:, None]))),
            "h": float(max(0.0, P.h_min - hn, hn - P.h_max)),
        },
        "activity": {
            "tolerance": f"a bound counts as active within {ACTIVE_REL:g} of its value (relative)",
            "torque_active": int(np.sum(np.abs(Un) >= P.u_max[:, None] * (1 - ACTIVE_REL))),
            "torque_entries": int(N * n),
            "torque_active_per_joint": np.sum(np.abs(Un) >= P.u_max[:, None] * (1 - ACTIVE_REL), axis=1).tolist(),
            "torque_peak_fraction_per_joint": (np.abs(Un).max(1) / P.u_max).tolist(),
            "velocity_active": int(np.sum(vel >= P.v_max[:, None] * (1 - ACTIVE_REL))),
            "velocity_entries": int(N * n),
            "velocity_active_per_joint": np.sum(vel >= P.v_max[:, None] * (1 - ACTIVE_REL), axis=1).tolist(),
            "velocity_peak_fraction_per_joint": (vel.max(1) / P.v_max).tolist(),
            "joint_limit_active": int(np.sum(
                (Qn[:, 1:N] <= P.robot.lower[:, None] + ACTIVE_REL * (P.robot.upper - P.robot.lower)[:, None]) |
                (Qn[:, 1:N] >= P.robot.upper[:, None] - ACTIVE_REL * (P.robot.upper - P.robot.lower)[:, None]))),
            "h_at": "h_min" if hn <= P.h_min * (1 + ACTIVE_REL) else ("h_max" if hn >= P.h_max * (1 - ACTIVE_REL) else "interior"),
        },
        "J": Jv.item(),
        "dynamics_residual_numeric": {
            "max_abs": float(np.abs(rn).max()),
            "max_abs_diff_to_casadi": float(np.abs(rn - res).max()),
            "max_diff_rel_to_terms": float((np.abs(rn - res) / np.maximum(sc, 1e-300)).max()),
            "note": ("the same equations in numpy on Pinocchio's double model (crba, computePotentialEnergy), "
                     "dL/dq by a 5-point central difference with step 1e-3: an independent re-evaluation, "
                     "accurate to the difference formula (~1e-9 relative)"),
        },
        "J_parts": {"time c_t·N·h": Jt.item(), "effort c_e·h·Σ|u|²": Je.item(), "velocity c_v·Σ|Δq|²/h": Jvel.item()},
        "h": hn,
        "duration": N * hn,
    }
    return out, (Qn, Un, hn, qd0n, qdNn)


def residual_numeric(robot, Qn, Un, hn, qd0, qdN):
    """The same equations in plain numpy on Pinocchio's double-precision model, independent of the
    CasADi expressions: dL/dv = crba(m) v, dL/dq by a 5-point central difference (step 1e-3) of
    L = 1/2 v^T crba(q) v - computePotentialEnergy(q). Returns the (N+1) x n residual rows."""
    m, d = robot.model, robot.data
    n, N = Qn.shape[0], Un.shape[1]

    def Mq(q):
        M = pin.crba(m, d, q)
        return np.triu(M) + np.triu(M, 1).T

    def L(q, v):
        return 0.5 * v @ Mq(q) @ v - pin.computePotentialEnergy(m, d, q)

    def Lq(q, v, e=1e-3):
        g = np.empty(n)
        for j in range(n):
            dq = np.zeros(n)
            dq[j] = e
            g[j] = (-L(q + 2 * dq, v) + 8 * L(q + dq, v) - 8 * L(q - dq, v) + L(q - 2 * dq, v)) / (12 * e)
        return g

    D1, D2 = [], []
    for i in range(N):
        a, b = Qn[:, i], Qn[:, i + 1]
        mid, v = (a + b) / 2, (b - a) / hn
        lq, lv = Lq(mid, v), Mq(mid) @ v
        D1.append(hn / 2 * lq - lv)
        D2.append(hn / 2 * lq + lv)
    rows = [Mq(Qn[:, 0]) @ qd0 + D1[0] + hn / 2 * Un[:, 0]]
    rows += [D2[k - 1] + D1[k] + hn / 2 * (Un[:, k - 1] + Un[:, k]) for k in range(1, N)]
    rows.append(-Mq(Qn[:, N]) @ qdN + D2[N - 1] + hn / 2 * Un[:, N - 1])
    return np.array(rows)


def solution_dict(Qn, Un, hn, qd0, qdN):
    return {"q": Qn.T.tolist(), "u": Un.T.tolist(), "h": hn, "qd0": np.ravel(qd0).tolist(), "qdN": np.ravel(qdN).tolist()}


def load_solution(P, path):
    with open(path) as f:
        s = json.load(f)
    s = s.get("solution", s)
    Q = np.array(s["q"], float)
    U = np.array(s["u"], float)
    n, N = P.robot.n, P.N
    if Q.shape != (N + 1, n) or U.shape != (N, n):
        sys.exit(f"solution shapes q {Q.shape}, u {U.shape}; expected ({N + 1}, {n}), ({N}, {n})")
    return P.pack(Q.T, U.T, s["h"], s.get("qd0", np.zeros(n)), s.get("qdN", np.zeros(n)))


# ---------------------------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("problem")
    ap.add_argument("--json", metavar="OUT")
    ap.add_argument("--check", metavar="SOLUTION")
    ap.add_argument("--tol", type=float, default=1e-10)
    ap.add_argument("--max-iter", type=int, default=3000)
    ap.add_argument("--print-level", type=int, default=0)
    ap.add_argument("--backend", choices=["auto", "cpin", "helper"], default="auto")
    ap.add_argument("--guess-h-factor", type=float, default=1.0,
                    help="multiply the initial guess's h by this (to probe for other local optima; default 1)")
    ap.add_argument("--guess-u", choices=["gravity", "zero"], default="gravity",
                    help="initial torques: gravity torques at the midpoints (default) or zero")
    ap.add_argument("--guess-seed", type=int, default=None,
                    help="add a smooth random detour (amplitude --guess-noise rad per joint, sin-shaped) to the "
                         "linear q guess, numpy default_rng(seed)")
    ap.add_argument("--guess-noise", type=float, default=0.3)
    ap.add_argument("--bound-relax-factor", type=float, default=0.0,
                    help="IPOPT bound_relax_factor (default here 0: the solution keeps every bound exactly; "
                         "IPOPT's own default 1e-8 lets bounds be crossed by 1e-8 relative, which moved J by up "
                         "to 1.2e-7 relative on bench/ocp/ur10_fast.json)")
    ap.add_argument("--no-expand", action="store_true", help="keep the NLP as MX (default: expand to SX)")
    args = ap.parse_args()

    with open(args.problem) as f:
        prob = json.load(f)
    t0 = time.perf_counter()
    robot = Robot(prob, args.backend)
    P = Problem(prob, robot)
    n, N = robot.n, P.N
    versions = {"casadi": ca.__version__, "ipopt": ipopt_version(), "pinocchio": pin.__version__,
                "numpy": np.__version__, "python": platform.python_version()}
    head = {
        "problem_file": os.path.relpath(os.path.abspath(args.problem), REPO),
        "problem": prob,
        "robot": {"urdf": os.path.relpath(robot.urdf, REPO), "root": robot.root_link, "joints": robot.joints,
                  "bodies": robot.bodies, "universe_mass": robot.universe_mass, "pruned_links": robot.pruned,
                  "lower": robot.lower.tolist(), "upper": robot.upper.tolist(),
                  "packages": robot.package_report},
        "limits": {"v_max": P.v_max.tolist(), "v_max_source": P.v_src, "u_max": P.u_max.tolist(),
                   "u_max_source": P.u_src, "h_min": P.h_min, "h_max": P.h_max},
        "weights": P.w,
        "dynamics_backend": robot.backend,
        "self_check": robot.self_check,
        "versions": versions,
        "variables": P.n_var,
        "constraints": P.n_eq + P.n_ineq,
        "constraints_equality": P.n_eq,
        "constraints_inequality": P.n_ineq,
        "variables_fixed_by_bounds": 4 * n,
    }

    if args.check:
        x = load_solution(P, args.check)
        ev, _ = evaluate(P, x)
        doc = dict(head, mode="check", solution_file=os.path.abspath(args.check), evaluation=ev)
        print_check(doc)
        write(args.json, doc)
        return

    w = ca.MX.sym("w", P.n_var)
    dyn, up, lo, J, _ = P.expressions(w)
    g = ca.vertcat(*[e for _, _, e in dyn], up, lo)
    opts = {
        "ipopt.tol": args.tol,
        "ipopt.max_iter": args.max_iter,
        "ipopt.print_level": args.print_level,
        "ipopt.sb": "yes",
        "ipopt.hessian_approximation": "exact",
        "print_time": False,
        "expand": not args.no_expand,
    }
    opts["ipopt.bound_relax_factor"] = args.bound_relax_factor
    solver = ca.nlpsol("dmoc", "ipopt", {"x": w, "f": J, "g": g}, opts)
    lbx, ubx, lbg, ubg = P.bounds()
    x0, guess = P.initial_guess(args.guess_h_factor, args.guess_u, args.guess_seed, args.guess_noise)
    t_build = time.perf_counter() - t0
    t1 = time.perf_counter()
    sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    t_solve = time.perf_counter() - t1
    st = solver.stats()
    x = np.array(sol["x"]).ravel()
    ev, (Qn, Un, hn, qd0n, qdNn) = evaluate(P, x)
    ev0, _ = evaluate(P, x0)
    doc = dict(head)
    doc.update({
        "mode": "solve",
        "ipopt_options": {k: v for k, v in opts.items()},
        "ipopt_defaults_note": ("all other IPOPT options at their defaults (mu_strategy monotone, acceptable_tol "
                                "1e-6 after 15 acceptable iterations, constr_viol_tol 1e-4, "
                                "fixed_variable_treatment make_parameter, nlp_scaling_method gradient-based, "
                                "linear_solver mumps); expand: the MX graph is expanded to SX before solving"),
        "initial_guess": {"h": guess["h"], "t_slowest_joint": guess["t_slowest_joint"], "h_factor": guess["h_factor"],
                          "u": guess["u"], "q_detour_seed": guess["q_detour_seed"],
                          "q_detour_amplitude": guess["q_detour_amplitude"], "J": ev0["J"],
                          "dynamics_residual_max_abs": ev0["dynamics_residual"]["max_abs"]},
        "status": st["return_status"],
        "success": bool(st["success"]),
        "J": float(sol["f"]),
        "duration": N * hn,
        "h": hn,
        "iterations": int(st["iter_count"]),
        "solve_wall_s": t_solve,
        "nlp_eval_wall_s": sum(v for k, v in st.items() if k.startswith("t_wall_nlp_")),
        "solve_time_note": ("solve_wall_s: wall-clock time of the solver call alone (IPOPT + CasADi's evaluations; "
                            "not the model building, the symbolic set-up or the expansion to SX before it); "
                            "nlp_eval_wall_s: the part spent in CasADi's evaluations of f, g, their derivatives and "
                            "the Hessian"),
        "setup_wall_s": t_build,
        "evaluation": ev,
        "solution": solution_dict(Qn, Un, hn, qd0n, qdNn),
    })
    print_solve(doc)
    write(args.json, doc)


def write(path, doc):
    if not path:
        return
    os.makedirs(os.path.dirname(os.path.abspath(path)) or ".", exist_ok=True)
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(f"wrote {path}")


def print_common(doc):
    r = doc["robot"]
    print(f"{doc['problem_file']}: {r['urdf']} ({len(r['joints'])} joints, moving mass "
          f"{sum(b['mass'] for b in r['bodies']):.6g} kg), N = {doc['problem']['N']}")
    print(f"  dynamics: {doc['dynamics_backend']}; self-check vs Pinocchio: M {doc['self_check']['M_rel']:.1e}, "
          f"T {doc['self_check']['T_rel']:.1e}, V {doc['self_check']['V_abs']:.1e} (abs), "
          f"dL/dq vs FD {doc['self_check']['dLdq_rel_fd']:.1e}")
    print(f"  variables {doc['variables']} ({doc['variables_fixed_by_bounds']} fixed by bounds), constraints "
          f"{doc['constraints']} ({doc['constraints_equality']} equality, {doc['constraints_inequality']} inequality)")
    v = doc["versions"]
    print(f"  CasADi {v['casadi']}, IPOPT {v['ipopt']}, Pinocchio {v['pinocchio']}")


def print_eval(ev):
    d, a = ev["dynamics_residual"], ev["activity"]
    print(f"  J = {ev['J']!r}  (time {ev['J_parts']['time c_t·N·h']:.6g}, effort {ev['J_parts']['effort c_e·h·Σ|u|²']:.6g}, "
          f"velocity {ev['J_parts']['velocity c_v·Σ|Δq|²/h']:.6g})")
    print(f"  duration N·h = {ev['duration']!r} s, h = {ev['h']!r} ({a['h_at']})")
    print(f"  dynamics residual max {d['max_abs']:.3e} (start {d['max_abs_start']:.1e}, interior "
          f"{d['max_abs_interior']:.1e}, end {d['max_abs_end']:.1e}; relative {d['max_rel']:.1e})")
    dn = ev["dynamics_residual_numeric"]
    print(f"  independent numpy/Pinocchio re-evaluation (dL/dq by 5-point differences): max residual "
          f"{dn['max_abs']:.3e}, differs from CasADi's by {dn['max_abs_diff_to_casadi']:.1e} "
          f"({dn['max_diff_rel_to_terms']:.1e} of the terms)")
    bv = ev["bound_violation"]
    print(f"  bound violations: " + ", ".join(f"{k} {v:.1e}" for k, v in bv.items()))
    print(f"  active: torque {a['torque_active']}/{a['torque_entries']} {a['torque_active_per_joint']}, "
          f"velocity {a['velocity_active']}/{a['velocity_entries']} {a['velocity_active_per_joint']}, "
          f"joint limits {a['joint_limit_active']}")
    print("  peak |u|/u_max " + " ".join(f"{x:.3f}" for x in a["torque_peak_fraction_per_joint"]) +
          "; peak |q̇|/v_max " + " ".join(f"{x:.3f}" for x in a["velocity_peak_fraction_per_joint"]))


def print_solve(doc):
    print_common(doc)
    print(f"  status {doc['status']}, {doc['iterations']} iterations, solve {doc['solve_wall_s']:.3f} s wall "
          f"(of which CasADi evaluations {doc['nlp_eval_wall_s']:.3f} s), tol {doc['ipopt_options']['ipopt.tol']:g}")
    print(f"  initial guess: h {doc['initial_guess']['h']:.6g}, J {doc['initial_guess']['J']:.6g}, "
          f"dynamics residual {doc['initial_guess']['dynamics_residual_max_abs']:.3e}")
    print_eval(doc["evaluation"])


def print_check(doc):
    print_common(doc)
    print(f"  check of {doc['solution_file']}")
    print_eval(doc["evaluation"])


if __name__ == "__main__":
    main()
