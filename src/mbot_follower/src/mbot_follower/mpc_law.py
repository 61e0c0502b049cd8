"""The predictive formation law (``controller: mpc``): every control period one quadratic
program (QP) over a receding horizon, solved by cvxopt. No ROS here.

Frame and prediction. Everything is in the frame of the control law's input (the leader frame,
or a column slot's own frame) at the current instant. The leader's twist (v_L, w_L) is held over
the horizon, so the frame moves along an arc: F_k = the frame after k steps of dt
(dt = mpc_step control periods), and the slot's predicted position is s_k = F_k * s.

The QP (N = mpc_horizon steps, u_k the command of step k, x_k = (x, y, theta) the robot):

    min   sum_k=1..N  q_p |pos(x_k) - s_k|^2 + q_h,k (theta_k - theta_ref,k)^2
        + sum_k=0..N-1  r_v |u_k - u_ref,k|^2 + r_c |u_k - u_k-1|^2        (u_-1 = the last command)
    s.t.  x_k+1 = f(x_k, u_k) linearised about a nominal trajectory (one QP per period)
          velocity limits on u_k, acceleration limits on u_k - u_k-1 (hard)
          n . (pos(x_k) - o) >= d     for laser points o near the nominal (half-planes)
          n . (pos(x_k) - q_j,k) >= d for the teammates' predicted positions q_j,k

f is the unicycle (u = (v, w): x += dt v cos(theta), y += dt v sin(theta), theta += dt w) or,
for an omni robot, u = (vx, vy, w) in the body frame. The nominal is the better (by the true,
nonlinear cost) of the last solution shifted by one period and a roll-out of slot tracking;
x_k = x_nom,k + G (U - U_nom) with G from the Jacobians along it. n is the unit vector from the
obstacle to the nominal position. u_ref is the slot's own velocity (feed-forward), theta_ref the
direction the slot moves (the frame's heading when it stands); the heading weight fades with
the nominal's distance from the slot (far away only the position counts).

Fallback: a solve that fails, is infeasible, or takes longer than mpc_time_budget (wall) is
dropped and slot tracking gives the command of this period; every fallback is counted by
reason (``fallbacks``).
"""
import math
import time

import numpy as np

from mbot_common.geometry import Pose2D, Twist2D, compose, relative
from mbot_follower.control_laws import SlotTracking, integrate, slot_velocity

try:
    import cvxopt
    import cvxopt.solvers
except ImportError:  # pragma: no cover - a clear error when the law is made, not at import
    cvxopt = None

CELL = 0.05             # laser points: one per cell of this size [m]
NEAR_EXTRA = 0.3        # a point is a constraint of step k if within distance + this of its nominal [m]
OCTAGON = math.cos(math.pi / 8)   # a norm limit as 8 half-planes, inside the circle
MAX_TIMES = 100000      # solve times kept for the statistics
ITERATIONS = 2          # QPs per period at most (the second about the first's plan)
STRAY = 0.01            # [m] the true model strays this far from the QP's linear plan: a second QP
SLACK_COST = 1000.0     # cost of a metre of distance not kept (soft distance constraints)


class MpcError(ValueError):
    """Bad input or settings of the predictive law (the message names the problem)."""


def _check_settings(config, dt):
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
        raise MpcError("mpc: the control period dt must be a finite time > 0 [s], got %r" % (dt,))
    horizon, step = config.mpc_horizon, config.mpc_step
    if isinstance(horizon, bool) or not isinstance(horizon, int) or horizon < 1:
        raise MpcError("mpc: mpc_horizon must be a whole number >= 1, got %r" % (horizon,))
    if isinstance(step, bool) or not isinstance(step, int) or step < 1:
        raise MpcError("mpc: mpc_step must be a whole number >= 1, got %r" % (step,))
    for key in ("mpc_time_budget", "mpc_q_position", "mpc_q_heading", "mpc_r_velocity", "mpc_r_change",
                "mpc_robot_distance", "mpc_obstacle_distance", "mpc_obstacle_range", "max_linear_vel",
                "max_angular_vel", "max_linear_accel", "max_angular_accel", "max_reverse_vel"):
        value = getattr(config, key)
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
            raise MpcError("mpc: %s must be a finite number >= 0, got %r" % (key, value))


def thin_points(points, reach, cell=CELL):
    """The laser points (an array (m, 2), relative to the robot) within `reach` [m], one per grid
    cell of `cell` [m] (the nearest to the robot): a scan of hundreds of points becomes fewer
    constraints, none more than a cell's diagonal from a point dropped."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    if not len(p):
        return p
    d = np.hypot(p[:, 0], p[:, 1])
    keep = d <= reach
    p, d = p[keep], d[keep]
    if not len(p):
        return p
    cells = np.floor(p / cell).astype(np.int64)
    key = cells[:, 0] * 1000003 + cells[:, 1]
    order = np.lexsort((d, key))
    first = np.ones(len(order), dtype=bool)
    first[1:] = key[order][1:] != key[order][:-1]
    return p[order[first]]


def _step(x, u, dt, omni):
    """x after driving u for dt (the QP's model: the motion along the mean heading of the step,
    theta + dt w / 2, within a fraction of a millimetre of the exact arc at these speeds)."""
    th = x[2] + 0.5 * dt * u[-1]
    c, s = math.cos(th), math.sin(th)
    if omni:
        vx, vy, w = u
        return np.array([x[0] + dt * (c * vx - s * vy), x[1] + dt * (s * vx + c * vy), x[2] + dt * w])
    v, w = u
    return np.array([x[0] + dt * v * c, x[1] + dt * v * s, x[2] + dt * w])


def _jacobians(x, u, dt, omni):
    """d step / d x (3, 3) and d step / d u (3, nu) at (x, u)."""
    th = x[2] + 0.5 * dt * u[-1]
    c, s = math.cos(th), math.sin(th)
    a = np.eye(3)
    if omni:
        vx, vy, _ = u
        dth = np.array([dt * (-s * vx - c * vy), dt * (c * vx - s * vy)])   # d position / d theta_mean
        a[:2, 2] = dth
        b = np.array([[dt * c, -dt * s, 0.5 * dt * dth[0]], [dt * s, dt * c, 0.5 * dt * dth[1]], [0.0, 0.0, dt]])
    else:
        v = u[0]
        dth = np.array([-dt * v * s, dt * v * c])
        a[:2, 2] = dth
        b = np.array([[dt * c, 0.5 * dt * dth[0]], [dt * s, 0.5 * dt * dth[1]], [0.0, dt]])
    return a, b


def rollout(x0, inputs, dt, omni):
    """States x_0..x_N (array (N+1, 3)) driving inputs (N, nu) from x0."""
    xs = [np.asarray(x0, dtype=float)]
    for u in inputs:
        xs.append(_step(xs[-1], u, dt, omni))
    return np.array(xs)


class MpcLaw(object):
    """compute(inp, config) -> Twist2D; after it, ``prediction`` holds the planned poses
    [(x, y, theta) at 0, dt, ..., N dt] in the input's frame and ``step_dt`` their spacing."""

    smooth = False   # its commands are planned within the limits: the command filter only limits

    def __init__(self):
        if cvxopt is None:
            raise MpcError("mpc: the control law 'mpc' needs cvxopt (Debian: apt-get install python3-cvxopt)")
        self.fallback_law = SlotTracking()
        self.solves = 0                 # QPs attempted
        self.fallbacks = 0              # periods that slot tracking commanded instead
        self.reasons = {}               # fallback reason -> count
        self.relaxed = 0                # solutions that could not keep a distance (slack > 1 mm)
        self.solve_times = []           # [s wall] each QP solved (also those over the budget)
        self.prediction = None
        self.linear_prediction = None   # the QP's own positions (N, 2): what its constraints hold for
        self.step_dt = None
        self.last_reason = None
        self._solution = None           # (inputs (N, nu), dt, omni) of the last solution

    # --- statistics ---------------------------------------------------------------------------

    def stats(self):
        """Counts and solve times [ms] (p50, p99, max) so far."""
        out = {"solves": self.solves, "fallbacks": self.fallbacks, "reasons": dict(self.reasons),
               "relaxed": self.relaxed}
        if self.solve_times:
            t = np.array(self.solve_times) * 1000.0
            out.update(solve_ms_p50=round(float(np.percentile(t, 50)), 3),
                       solve_ms_p99=round(float(np.percentile(t, 99)), 3), solve_ms_max=round(float(t.max()), 3))
        return out

    def _fallback(self, reason, inp, config):
        self.fallbacks += 1
        self.reasons[reason] = self.reasons.get(reason, 0) + 1
        self.last_reason = reason
        self._solution = None
        return self.fallback_law.compute(inp, config)

    def _predict_fallback(self, inp, config):
        """The prediction of a period slot tracking commands: its roll-out (for the teammates)."""
        dt = inp.dt * config.mpc_step
        prev = inp.previous if inp.previous is not None else Twist2D(0.0, 0.0, 0.0)
        u_prev = np.array([prev.vx, prev.vy, prev.wz]) if config.omni else np.array([prev.vx, prev.wz])
        x0 = np.array([inp.pose.x, inp.pose.y, inp.pose.theta])
        inputs = self._slot_tracking_inputs(x0, inp, config, dt, config.mpc_horizon, u_prev)
        self.step_dt = dt
        self.prediction = rollout(x0, inputs, dt, bool(config.omni))

    # --- the law ------------------------------------------------------------------------------

    def compute(self, inp, config):
        _check_settings(config, inp.dt)
        pose, twist = inp.pose, inp.leader_twist
        values = list(pose) + list(inp.slot) + list(twist)
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in values):
            raise MpcError("mpc: pose, slot and leader twist must be finite, got %r %r %r"
                           % (tuple(pose), tuple(inp.slot), tuple(twist)))
        started = time.perf_counter()
        self.solves += 1
        try:
            cmd, reason = self._solve(inp, config)
        except (ArithmeticError, ValueError) as error:   # cvxopt: singular KKT system, rank
            cmd, reason = None, "solver error: %s" % str(error).splitlines()[0][:60]
        elapsed = time.perf_counter() - started
        if reason is None or not reason.startswith("solver error"):
            self.solve_times.append(elapsed)
            del self.solve_times[:-MAX_TIMES]
        if reason is None and elapsed > config.mpc_time_budget:
            reason = "time"
        if reason is not None:
            self._predict_fallback(inp, config)
            return self._fallback(reason, inp, config)
        self.last_reason = None
        return cmd

    def _reference(self, inp, config, dt, n):
        """Slot positions (N, 2), heading references (N,) and slot velocities (N, 2) at steps 1..N."""
        twist = inp.leader_twist
        vs = slot_velocity(inp.slot, twist)
        slots, headings, velocities = [], [], []
        frame = Pose2D(0.0, 0.0, 0.0)
        for _ in range(n):
            frame = integrate(frame, twist, dt)
            s = compose(frame, Pose2D(inp.slot[0], inp.slot[1], 0.0))
            c, si = math.cos(frame.theta), math.sin(frame.theta)
            v = (c * vs[0] - si * vs[1], si * vs[0] + c * vs[1])
            slots.append((s.x, s.y))
            velocities.append(v)
            moving = math.hypot(*v) > 0.05 and not config.omni
            headings.append(math.atan2(v[1], v[0]) if moving else frame.theta)
        return np.array(slots), np.array(headings), np.array(velocities)

    def _slot_tracking_inputs(self, x0, inp, config, dt, n, u_prev):
        """Slot tracking rolled out over the horizon in the model (limited like the filter)."""
        nu = 3 if config.omni else 2
        inputs, x, prev = [], np.array(x0), np.array(u_prev, dtype=float)
        frame = Pose2D(0.0, 0.0, 0.0)
        for _ in range(n):
            me = relative(frame, Pose2D(*x))
            cmd = self.fallback_law.compute(inp._replace(pose=me), config)
            u = np.array([cmd.vx, cmd.vy, cmd.wz]) if nu == 3 else np.array([cmd.vx, cmd.wz])
            u = self._limit(u, prev, config, dt)
            inputs.append(u)
            prev = u
            x = _step(x, u, dt, config.omni)
            frame = integrate(frame, inp.leader_twist, dt)
        return np.array(inputs)

    @staticmethod
    def _limit(u, prev, config, dt):
        u = np.array(u, dtype=float)
        lin = slice(0, len(u) - 1)
        d = u[lin] - prev[lin]
        norm = np.linalg.norm(d)
        if norm > config.max_linear_accel * dt:
            u[lin] = prev[lin] + d * config.max_linear_accel * dt / norm
        u[-1] = prev[-1] + np.clip(u[-1] - prev[-1], -config.max_angular_accel * dt, config.max_angular_accel * dt)
        if len(u) == 3:
            norm = np.linalg.norm(u[:2])
            if norm > config.max_linear_vel * OCTAGON:
                u[:2] *= config.max_linear_vel * OCTAGON / norm
        else:
            u[0] = np.clip(u[0], -config.max_reverse_vel, config.max_linear_vel)
        u[-1] = np.clip(u[-1], -config.max_angular_vel, config.max_angular_vel)
        return u

    def _cost(self, xs, inputs, ref, config, u_prev):
        """The true (nonlinear) cost of a trajectory, to choose the nominal."""
        slots, headings, velocities = ref
        e = xs[1:, :2] - slots
        cost = config.mpc_q_position * float(np.sum(e * e))
        dist = np.hypot(e[:, 0], e[:, 1])
        dh = np.remainder(xs[1:, 2] - headings + math.pi, 2 * math.pi) - math.pi
        cost += float(np.sum(config.mpc_q_heading / (1.0 + (dist / 0.2) ** 2) * dh * dh))
        du = np.diff(np.vstack([u_prev, inputs]), axis=0)
        return cost + config.mpc_r_change * float(np.sum(du * du))

    def _solve(self, inp, config):
        """(Twist2D, None) or (None, the reason for a fallback)."""
        omni = bool(config.omni)
        nu = 3 if omni else 2
        period = float(inp.dt)
        dt = period * config.mpc_step
        n = config.mpc_horizon
        prev = inp.previous if inp.previous is not None else Twist2D(0.0, 0.0, 0.0)
        u_prev = np.array([prev.vx, prev.vy, prev.wz]) if omni else np.array([prev.vx, prev.wz])
        x0 = np.array([inp.pose.x, inp.pose.y, inp.pose.theta])
        ref = self._reference(inp, config, dt, n)
        slots, headings, velocities = ref

        # the nominal: the last solution a period on, or slot tracking rolled out, the cheaper
        candidates = [self._slot_tracking_inputs(x0, inp, config, dt, n, u_prev)]
        if self._solution is not None and self._solution[1:] == (dt, omni) and len(self._solution[0]) == n:
            old = self._solution[0]
            times = (np.arange(n) * dt + period) / dt
            candidates.append(old[np.minimum(times.astype(int), n - 1)])
        best = None
        for u_nom in candidates:
            xs = rollout(x0, u_nom, dt, omni)
            cost = self._cost(xs, u_nom, ref, config, u_prev)
            if best is None or cost < best[0]:
                best = (cost, u_nom, xs)
        _, u_nom, xs = best
        # one QP about the nominal; if its plan, driven through the true model, strays from the
        # QP's linear prediction by more than STRAY, a second one about that plan
        for iteration in range(ITERATIONS):
            out = self._qp(inp, config, x0, u_nom, xs, ref, u_prev, dt, period, n, nu, omni)
            if isinstance(out, str):
                return None, out
            inputs, linear, slack = out
            xs_new = rollout(x0, inputs, dt, omni)
            stray = float(np.max(np.hypot(*(xs_new[1:, :2] - linear).T)))
            u_nom, xs = inputs, xs_new
            if stray <= STRAY:
                break
        if np.max(slack) > 1e-3:
            self.relaxed += 1   # a distance could not be kept (the safety layer still stops the robot)
        self._solution = (inputs, dt, omni)
        self.step_dt = dt
        self.prediction = xs
        self.linear_prediction = linear
        u = inputs[0]
        return (Twist2D(u[0], u[1], u[2]) if omni else Twist2D(u[0], 0.0, u[1])), None

    def _qp(self, inp, config, x0, u_nom, xs, ref, u_prev, dt, period, n, nu, omni):
        """The QP linearised about (u_nom, xs): (inputs (N, nu), the QP's positions (N, 2), slacks
        (N,)) or the reason it has no solution."""
        slots, headings, velocities = ref
        # x_k = xs_k + G_k (U - U_nom): sensitivities along the nominal
        nv = nu * n
        sens = np.zeros((n + 1, 3, nv))
        for k in range(n):
            a, b = _jacobians(xs[k], u_nom[k], dt, omni)
            sens[k + 1] = a.dot(sens[k])
            sens[k + 1][:, k * nu:(k + 1) * nu] += b
        gpos = sens[1:, :2, :]           # (N, 2, nv)
        gth = sens[1:, 2, :]             # (N, nv)

        # cost in dU = U - U_nom: 1/2 dU' P dU + q' dU
        e = xs[1:, :2] - slots           # (N, 2)
        dist = np.hypot(e[:, 0], e[:, 1])
        qh = config.mpc_q_heading / (1.0 + (dist / 0.2) ** 2)
        dh = np.remainder(xs[1:, 2] - headings + math.pi, 2 * math.pi) - math.pi
        gp = gpos.reshape(2 * n, nv)
        P = 2.0 * config.mpc_q_position * gp.T.dot(gp) + 2.0 * (gth.T * qh).dot(gth)
        q = 2.0 * config.mpc_q_position * gp.T.dot(e.reshape(-1)) + 2.0 * gth.T.dot(qh * dh)
        # the slot's own velocity as each step's reference command (feed-forward)
        u_ref = np.zeros((n, nu))
        for k in range(n):
            c, s = math.cos(xs[k, 2]), math.sin(xs[k, 2])
            v = velocities[k]
            if omni:
                u_ref[k] = (c * v[0] + s * v[1], -s * v[0] + c * v[1], inp.leader_twist.wz)
            else:
                u_ref[k] = (c * v[0] + s * v[1], inp.leader_twist.wz)
        P += 2.0 * config.mpc_r_velocity * np.eye(nv)
        q += 2.0 * config.mpc_r_velocity * (u_nom - u_ref).reshape(-1)
        # change from step to step: D U - d, d = (u_prev, 0, ...)
        dmat = np.eye(nv) - np.eye(nv, k=-nu)
        d = np.zeros(nv)
        d[:nu] = u_prev
        r_change = dmat.dot(u_nom.reshape(-1)) - d
        P += 2.0 * config.mpc_r_change * dmat.T.dot(dmat)
        q += 2.0 * config.mpc_r_change * dmat.T.dot(r_change)
        P += 1e-6 * np.eye(nv)

        rows, bounds = [], []
        flat = u_nom.reshape(-1)
        eye = np.eye(nv)
        # velocity limits (hard)
        lo = np.tile([-config.max_linear_vel, -config.max_linear_vel, -config.max_angular_vel] if omni
                     else [-config.max_reverse_vel, -config.max_angular_vel], n)
        hi = np.tile([config.max_linear_vel, config.max_linear_vel, config.max_angular_vel] if omni
                     else [config.max_linear_vel, config.max_angular_vel], n)
        rows += [eye, -eye]
        bounds += [hi - flat, flat - lo]
        # acceleration limits: the first step against the last command (one period), then per step
        steps = np.full(n, dt)
        steps[0] = period
        amax = np.repeat(steps, nu) * np.tile([config.max_linear_accel] * (nu - 1) + [config.max_angular_accel], n)
        if omni:
            # |(vx, vy)| and |(dvx, dvy)| limited as octagons (inside the circle): 8 half-planes
            dirs = np.array([(math.cos(a), math.sin(a)) for a in np.arange(8) * math.pi / 4])
            sel = np.zeros((n, 8, nv))
            for k in range(n):
                sel[k, :, k * nu:k * nu + 2] = dirs
            sel = sel.reshape(8 * n, nv)
            rows += [sel, sel.dot(dmat)]
            bounds += [config.max_linear_vel * OCTAGON - sel.dot(flat),
                       np.repeat(steps, 8) * config.max_linear_accel * OCTAGON - sel.dot(r_change)]
            ang = eye[nu - 1::nu]
            rows += [ang.dot(dmat), -ang.dot(dmat)]
            bounds += [ang.dot(amax) - ang.dot(r_change), ang.dot(amax) + ang.dot(r_change)]
        else:
            rows += [dmat, -dmat]
            bounds += [amax - r_change, amax + r_change]
        # distances: half-planes about the nominal positions
        p0 = x0[:2]
        nominal = xs[1:, :2]
        soft_rows, bounds_soft = [], []

        def half_planes(points_by_step, distance):
            for k, points in points_by_step:
                if not len(points):
                    continue
                diff = nominal[k] - points
                norm = np.hypot(diff[:, 0], diff[:, 1])
                # already closer now than the distance: not closer than now (else it is infeasible)
                now = np.hypot(*(p0 - points).T)
                need = np.minimum(distance, now - 1e-3)
                near = norm < need + NEAR_EXTRA
                if not np.any(near):
                    continue
                diff, norm, pts, need = diff[near], np.maximum(norm[near], 1e-6), points[near], need[near]
                # a nominal that passed through the point to its far side would put the robot
                # there: the side the robot is on now counts instead
                back = (p0 - pts)
                far = np.sum(diff * back, axis=1) < 0.0
                diff[far], norm[far] = back[far], np.maximum(np.hypot(*back[far].T), 1e-6)
                normal = diff / norm[:, None]
                row = np.zeros((len(pts), nv + n))
                row[:, :nv] = -normal.dot(gpos[k])
                row[:, nv + k] = -1.0   # the step's slack
                soft_rows.append(row)
                bounds_soft.append(np.sum(normal * (nominal[k] - pts), axis=1) - need)

        if len(inp.obstacles):
            obstacles = np.asarray(inp.obstacles, dtype=float).reshape(-1, 2)
            rel = thin_points(obstacles - p0, config.mpc_obstacle_range) + p0
            half_planes([(k, rel) for k in range(n)], config.mpc_obstacle_distance)
        for path in inp.teammates:
            path = np.asarray(path, dtype=float).reshape(-1, 2)
            if len(path) < n + 1:
                path = np.vstack([path, np.repeat(path[-1:], n + 1 - len(path), axis=0)])
            half_planes([(k, path[k + 1:k + 2]) for k in range(n)], config.mpc_robot_distance)

        # the distances are soft: a slack s_k >= 0 per step at SLACK_COST per metre (an exact
        # penalty: where the distances can be kept, the solution keeps them); the limits are hard
        hard = np.hstack([np.vstack(rows), np.zeros((sum(len(r) for r in rows), n))])
        G = np.vstack([hard, np.hstack([np.zeros((n, nv)), -np.eye(n)])] + soft_rows)
        h = np.concatenate(bounds + [np.zeros(n)] + bounds_soft)
        P_full = np.zeros((nv + n, nv + n))
        P_full[:nv, :nv] = P
        P_full[nv:, nv:] = 2.0 * np.eye(n)
        q_full = np.concatenate([q, np.full(n, SLACK_COST)])
        result = cvxopt.solvers.qp(cvxopt.matrix(P_full), cvxopt.matrix(q_full), cvxopt.matrix(G), cvxopt.matrix(h),
                                   options={"show_progress": False, "maxiters": 30})
        if result["status"] != "optimal":
            return "solver: %s" % result["status"]
        z = np.array(result["x"]).reshape(-1)
        if np.max(G.dot(z) - h) > 1e-5 * max(1.0, float(np.max(np.abs(h)))):
            return "infeasible"
        du, slack = z[:nv], z[nv:]
        inputs = np.clip((flat + du).reshape(n, nu), lo.reshape(n, nu), hi.reshape(n, nu))   # round-off only
        return inputs, nominal + gpos.dot(du), slack
