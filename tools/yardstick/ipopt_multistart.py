"""An independent yardstick of a scenario's take-off plan: the optimal control problem of
docs/FORMULATION.md transcribed anew (Hermite–Simpson collocation, not the planner's LGR)
in CasADi and solved by IPOPT with exact second derivatives from several starts: straight
and bulged paths through the targets built here, and any plan.json given (e.g. the
planner's own). Each solution is judged by the customer's judge (tools/judge/evaluate.py:
the metrics of the path as given, as a plan flown by a tracker is judged), and the best
judged cost is the yardstick.

    python3 tools/yardstick/ipopt_multistart.py SCENARIO.toml [PLAN.json ...] [--nodes-per-s 0.2]

Prints one JSON object: every start's IPOPT status, NLP objective and judged cost, and the
best. Needs casadi (pip install casadi==3.8.2) besides the judge's numpy and scipy.
Static threats known at take-off and moving threats on two-point roads are supported (the
campaign's); events and pop-ups are not part of the take-off problem.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "judge"))
from scenario import G0, exposure_eps, load_scenario  # noqa: E402
from evaluate import evaluate  # noqa: E402

import casadi as ca  # noqa: E402


def f_dyn(sc, x, u):
    V = sc.vehicle.V
    if sc.model == "2d":
        return ca.vertcat(V * ca.cos(x[2]), V * ca.sin(x[2]), u[0])
    gam, chi, nz, mu = x[3], x[4], x[5], x[6]
    return ca.vertcat(
        V * ca.cos(gam) * ca.cos(chi),
        V * ca.cos(gam) * ca.sin(chi),
        V * ca.sin(gam),
        G0 * (nz * ca.cos(mu) - ca.cos(gam)) / V,
        G0 * nz * ca.sin(mu) / (V * ca.cos(gam)),
        u[0],
        u[1],
    )


def abs_pow(v, p):
    """|v|^p, smooth enough at 0 for p >= 2."""
    return (v * v + 1e-12) ** (p / 2.0)


def exposure(sc, p, t):
    statics, movings = sc.known_threats()
    prod = 1.0
    for th in statics:
        d = [p[i] - th.center[i] for i in range(sc.dim)]
        c, s = math.cos(th.yaw), math.sin(th.yaw)
        dx, dy = c * d[0] + s * d[1], -s * d[0] + c * d[1]
        F = abs_pow(dx / th.axes[0], th.exponents[0]) + abs_pow(dy / th.axes[1], th.exponents[1])
        if sc.dim == 3:
            F = F + abs_pow(d[2] / th.axes[2], th.exponents[2])
        prod = prod * exposure_eps(F, sc.stiffness, lib=ca)
    for m in movings:
        if len(m.road) != 2:
            raise SystemExit(f"moving threat {m.name}: only two-point roads are supported")
        seg = m.road[1] - m.road[0]
        L = float(np.linalg.norm(seg[:2])) if sc.dim == 2 else float(np.linalg.norm(seg))
        yaw = math.atan2(seg[1], seg[0])
        sig = m.sigma_d(t, lib=ca)
        dist = m.mean_d(t)
        c = [m.road[0][i] + dist / L * seg[i] for i in range(sc.dim)]
        d = [p[i] - c[i] for i in range(sc.dim)]
        dx = math.cos(yaw) * d[0] + math.sin(yaw) * d[1]
        dy = -math.sin(yaw) * d[0] + math.cos(yaw) * d[1]
        ax = m.axes0[0] + sig
        px = 2.0 + sig / m.axes0[0]
        F = abs_pow(dx / ax, px) + (dy / m.axes0[1]) ** 2
        if sc.dim == 3:
            F = F + (d[2] / m.axes0[2]) ** 2
        # Counts from its appearance (all take-off moving threats appeared by t0).
        prod = prod * exposure_eps(F, sc.stiffness, lib=ca)
    return 1.0 - prod


def running_cost(sc, x, u, t):
    effort = ca.sumsqr(u)
    return (1.0 - sc.beta) * effort + sc.beta * exposure(sc, x[: sc.dim], t)


def waypoints(sc):
    pts = [sc.x0[: sc.dim]] + [np.asarray(t[: sc.dim], float) for t in sc.targets]
    if sc.final_state is not None:
        pts.append(sc.final_state[: sc.dim])
    else:
        # A point ahead on the lead's route: where a straight dash would meet it.
        pos, _, _ = sc.lead.state(np.array([sc.t0]))
        tf = sc.t0 + sum(np.linalg.norm(b - a) for a, b in zip(pts[:-1], pts[1:])) / sc.vehicle.V * 1.5 + 60
        pos, _, _ = sc.lead.state(np.array([tf]))
        pts.append(pos[0][: sc.dim])
    return pts


def straight_guess(sc, bulge):
    """Times, states and controls of a path through the waypoints, each leg a circular-ish
    arc bulged by `bulge` times its length to the left (0: straight)."""
    pts = waypoints(sc)
    V = sc.vehicle.V
    ts, xs, phase_ends = [], [], []
    t = sc.t0
    for a, b in zip(pts[:-1], pts[1:]):
        n = 60
        mid = (a + b) / 2.0
        dvec = b - a
        normal = np.array([-dvec[1], dvec[0]] + ([0.0] if sc.dim == 3 else [])) / max(np.linalg.norm(dvec[:2]), 1.0)
        ctrl = mid + bulge * np.linalg.norm(dvec[:2]) * normal
        s = np.linspace(0.0, 1.0, n + 1)
        pos = ((1 - s) ** 2)[:, None] * a + (2 * s * (1 - s))[:, None] * ctrl + (s**2)[:, None] * b
        seg = np.linalg.norm(np.diff(pos, axis=0), axis=1)
        tt = t + np.concatenate([[0.0], np.cumsum(seg)]) / V
        start = 0 if not ts else 1
        for k in range(start, n + 1):
            ts.append(tt[k])
            xs.append(pos[k])
        t = tt[-1]
        phase_ends.append(t)
    ts = np.array(ts)
    P = np.array(xs)
    dP = np.gradient(P, ts, axis=0)
    head = np.unwrap(np.arctan2(dP[:, 1], dP[:, 0]))
    head += 2 * math.pi * round((sc.x0[sc.heading_index] - head[0]) / (2 * math.pi))
    if sc.model == "2d":
        X = np.column_stack([P, head])
        U = np.gradient(head, ts)[:, None]
    else:
        gam = np.arctan2(dP[:, 2], np.hypot(dP[:, 0], dP[:, 1]))
        X = np.column_stack([P, gam, head, np.ones_like(ts), np.zeros_like(ts)])
        U = np.zeros((len(ts), 2))
    return ts, X, U, phase_ends


def plan_guess(sc, path):
    d = json.loads(Path(path).read_text())
    t = np.asarray(d["times"], float)
    X = np.asarray(d["states"], float)
    U = np.asarray(d["controls"], float)
    ends = [e for e in d["phase_ends_s"]] if d.get("phase_ends_s") else [t[-1]]
    return t, X, U, ends


def solve(sc, guess, nodes_per_s, max_iter):
    tg, Xg, Ug, ends_g = guess
    phases = len(sc.targets) + 1
    if len(ends_g) != phases:
        return {"status": f"guess has {len(ends_g)} phases, the problem {phases}"}
    nx, nu, dim = sc.nx, sc.nu, sc.dim
    opti = ca.Opti()
    T = opti.variable(phases)
    bounds_lo = np.full(nx, -np.inf)
    bounds_hi = np.full(nx, np.inf)
    v = sc.vehicle
    if sc.model == "3d":
        bounds_lo[2], bounds_lo[3], bounds_hi[3] = v.z_min, -v.gamma_max, v.gamma_max
        bounds_lo[5], bounds_hi[5], bounds_lo[6], bounds_hi[6] = v.nz_min, v.nz_max, -v.mu_max, v.mu_max
        u_max = np.array([v.nz_rate_max, v.mu_rate_max])
    else:
        u_max = np.array([v.u_max])

    def interp(tq, A):
        return np.column_stack([np.interp(tq, tg, A[:, i]) for i in range(A.shape[1])])

    J_run = 0
    t_prev = sc.t0
    t_prev_guess = tg[0]
    x_prev = None
    heads = []
    for g in range(phases):
        dur_g = ends_g[g] - t_prev_guess
        N = max(8, int(math.ceil(dur_g * nodes_per_s)))
        X = opti.variable(nx, N + 1)
        Xm = opti.variable(nx, N)
        U = opti.variable(nu, N + 1)
        Um = opti.variable(nu, N)
        t_start = t_prev
        h = (T[g] - t_start) / N
        opti.subject_to(T[g] - t_start >= 1.0)
        if x_prev is None:
            opti.subject_to(X[:, 0] == sc.x0)
        else:
            opti.subject_to(X[:, 0] == x_prev)
        tq = np.linspace(t_prev_guess, ends_g[g], N + 1)
        tqm = (tq[:-1] + tq[1:]) / 2
        opti.set_initial(X, interp(tq, Xg).T)
        opti.set_initial(Xm, interp(tqm, Xg).T)
        opti.set_initial(U, interp(tq, Ug).T)
        opti.set_initial(Um, interp(tqm, Ug).T)
        opti.set_initial(T[g], ends_g[g])
        for k in range(N):
            tk = t_start + k * h
            fk = f_dyn(sc, X[:, k], U[:, k])
            fk1 = f_dyn(sc, X[:, k + 1], U[:, k + 1])
            fm = f_dyn(sc, Xm[:, k], Um[:, k])
            opti.subject_to(X[:, k + 1] - X[:, k] - h / 6 * (fk + 4 * fm + fk1) == 0)
            opti.subject_to(Xm[:, k] - (X[:, k] + X[:, k + 1]) / 2 - h / 8 * (fk - fk1) == 0)
            Lk = running_cost(sc, X[:, k], U[:, k], tk)
            Lm = running_cost(sc, Xm[:, k], Um[:, k], tk + h / 2)
            Lk1 = running_cost(sc, X[:, k + 1], U[:, k + 1], tk + h)
            J_run = J_run + h / 6 * (Lk + 4 * Lm + Lk1)
        for A in (X, Xm):
            for i in range(nx):
                if np.isfinite(bounds_lo[i]):
                    opti.subject_to(A[i, :] >= bounds_lo[i])
                if np.isfinite(bounds_hi[i]):
                    opti.subject_to(A[i, :] <= bounds_hi[i])
        for A in (U, Um):
            for i in range(nu):
                opti.subject_to(opti.bounded(-u_max[i], A[i, :], u_max[i]))
        if g < len(sc.targets):
            opti.subject_to(X[:dim, N] == sc.targets[g][:dim])
        x_prev = X[:, N]
        heads.append((X, Xm, U, Um, N, t_start))
        t_prev = T[g]
        t_prev_guess = ends_g[g]
    hi = sc.heading_index
    tf = T[phases - 1]
    guess_head = Xg[-1, hi]
    if sc.final_state is not None:
        xf = np.array(sc.final_state, float)
        xf[hi] += 2 * math.pi * round((guess_head - xf[hi]) / (2 * math.pi))
        opti.subject_to(x_prev == xf)
    else:
        pos, chi, gam = sc.lead.casadi_state(tf)
        _, chi_g, _ = sc.lead.state(np.array([ends_g[-1]]))
        k2pi = 2 * math.pi * round((guess_head - chi_g[0]) / (2 * math.pi))
        opti.subject_to(x_prev[:dim] == pos)
        opti.subject_to(x_prev[hi] == chi + k2pi)
        if sc.model == "3d":
            opti.subject_to(x_prev[3] == gam)
            opti.subject_to(x_prev[5] == 1.0)
            opti.subject_to(x_prev[6] == 0.0)
    if sc.objective == "fixed-time":
        opti.subject_to(tf == sc.t_fixed)
        J = J_run
    else:
        J = sc.alpha * tf + (1 - sc.alpha) * J_run
    opti.minimize(J)
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "max_iter": max_iter, "tol": 1e-8, "sb": "yes"})
    try:
        sol = opti.solve()
        status = "Solve_Succeeded"
    except RuntimeError:
        sol = opti.debug
        status = opti.stats().get("return_status", "failed")
    # The solution densely: nodes and midpoints, controls linear between them.
    ts, Xs, Us = [], [], []
    Tv = np.atleast_1d(sol.value(T))
    for g, (X, Xm, U, Um, N, _) in enumerate(heads):
        t_start = sc.t0 if g == 0 else Tv[g - 1]
        h = (Tv[g] - t_start) / N
        Xv, Xmv, Uv, Umv = (np.atleast_2d(sol.value(A)) for A in (X, Xm, U, Um))
        if Xv.shape[0] != nx:
            Xv, Xmv, Uv, Umv = Xv.T, Xmv.T, Uv.T, Umv.T
        for k in range(N):
            if g > 0 and k == 0:
                pass
            ts += [t_start + k * h, t_start + (k + 0.5) * h]
            Xs += [Xv[:, k], Xmv[:, k]]
            Us += [Uv[:, k], Umv[:, k]]
        if g == phases - 1:
            ts.append(Tv[g])
            Xs.append(Xv[:, N])
            Us.append(Uv[:, N])
    ts = np.array(ts)
    keep = np.concatenate([[True], np.diff(ts) > 1e-9])
    ts, Xs, Us = ts[keep], np.array(Xs)[keep], np.array(Us)[keep]
    # Judged as given (the states themselves, by cubic Hermite splines with the model's
    # velocities), as a plan flown by a tracker is: an open-loop replay of sparse samples
    # drifts. The largest defect of one sample interval's replay tells the states obey the
    # dynamics.
    judged = evaluate(sc, ts, Xs, Us, phase_times=list(Tv))
    given = judged["as_given"]
    return {
        "status": status,
        "nlp_objective": float(sol.value(J)),
        "judged_cost": float(given["cost"]),
        "final_pos_err_m": float(given["final_pos_err_m"]),
        "segment_defect_pos_max_m": float(judged.get("segment_defect_pos_max_m", math.nan)),
        "final_time_s": float(Tv[-1]),
    }


def finite_json(v):
    """`v` with every non-finite float as None: JSON has no NaN, and a strict reader
    (the campaign's) refuses the whole document for one."""
    if isinstance(v, float):
        return v if math.isfinite(v) else None
    if isinstance(v, dict):
        return {k: finite_json(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [finite_json(x) for x in v]
    return v


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario")
    ap.add_argument("plans", nargs="*", help="plan.json files to start from as well")
    ap.add_argument("--nodes-per-s", type=float, default=0.2, help="Hermite-Simpson intervals per second of flight")
    ap.add_argument("--max-iter", type=int, default=1500)
    ap.add_argument("--bulges", default="0,0.25,-0.25", help="bulge ratios of the built starts")
    a = ap.parse_args(argv)
    sc = load_scenario(a.scenario)
    starts = [(f"bulge {b}", straight_guess(sc, float(b))) for b in a.bulges.split(",") if b]
    starts += [(p, plan_guess(sc, p)) for p in a.plans]
    results = []
    for name, guess in starts:
        try:
            r = solve(sc, guess, a.nodes_per_s, a.max_iter)
        except Exception as e:  # a start that cannot be set up is reported, not fatal
            r = {"status": f"error: {e}"}
        r["start"] = name
        results.append(r)
    ok = [r for r in results if r.get("status") == "Solve_Succeeded" and math.isfinite(r.get("judged_cost", math.nan))]
    best = min(ok, key=lambda r: r["judged_cost"]) if ok else None
    doc = finite_json({"scenario": sc.name, "starts": results, "best": best})
    print(json.dumps(doc, indent=2, allow_nan=False))
    return 0 if best else 1


if __name__ == "__main__":
    sys.exit(main())
