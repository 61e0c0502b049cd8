"""The summary statistics of a Run (metrics.json): summarize() and the rules it uses (see
mbot_follower.metrics for what the numbers mean)."""
import bisect
import math

import numpy as np

from mbot_follower.metrics.records import PLAN_STATES


def _number(value):
    """A float for JSON: None for NaN (no data)."""
    value = float(value)
    return value if math.isfinite(value) else None


def _finite(values):
    v = np.asarray(values, dtype=float)
    return v[np.isfinite(v)]


def finite_rms(values):
    """RMS of the finite values; None when there are none."""
    v = _finite(values)
    return _number(np.sqrt(np.mean(v * v))) if len(v) else None


def _stats(values, prefix, unit, rms=False, percentiles=()):
    """{prefix_rms_unit, prefix_pNN_unit..., prefix_max_unit} of the finite values (None: none).
    Percentiles interpolate linearly between the sorted values (numpy's default)."""
    v = _finite(values)
    out = {}
    if rms:
        out["%s_rms_%s" % (prefix, unit)] = finite_rms(v)
    for p in percentiles:
        out["%s_p%d_%s" % (prefix, p, unit)] = _number(np.percentile(v, p)) if len(v) else None
    out["%s_max_%s" % (prefix, unit)] = _number(np.max(v)) if len(v) else None
    return out


def _controller_stats(rows):
    """Latency p50/p95/max, tf success rate (newest counters per robot), cycle time p99 and the
    overruns and late starts (newest counters per robot, summed)."""
    newest = {}
    for row in rows:
        newest[row.robot] = row
    lookups = sum(r.lookups for r in newest.values())
    failures = sum(r.lookup_failures for r in newest.values())
    out = _stats([r.latency for r in rows], "latency", "s", percentiles=(50, 95))
    out["tf_success_rate"] = 1.0 - failures / float(lookups) if lookups > 0 else None
    out["cycle_time_p99_ms"] = _stats([r.cycle_time_ms for r in rows], "cycle_time", "ms",
                                      percentiles=(99,))["cycle_time_p99_ms"]
    # beside the cycle time: how often a controller missed its period (newest counters per robot)
    out["cycle_overruns"] = sum(r.overruns for r in newest.values())
    out["cycle_late_starts"] = sum(r.late_starts for r in newest.values())
    out["commands_not_applied"] = sum(1 for r in rows if r.applied == 0.0)   # dropped or replaced before a step
    return out


def run_span(run):
    """(start, end) sim time [s] of everything in the run; (0, 0) when it is empty."""
    times = [s.t for s in run.samples] + [e.t for e in run.events] + [c.t for c in run.controller]
    return (min(times), max(times)) if times else (0.0, 0.0)


def time_in_states(events, end):
    """{state: seconds} from the state events (sorted by time) up to `end` [s]."""
    changes = sorted((e for e in events if e.kind == "state"), key=lambda e: e.t)
    spent = {}
    for e, after in zip(changes, changes[1:] + [None]):
        until = after.t if after is not None else max(end, e.t)
        spent[e.name] = spent.get(e.name, 0.0) + (until - e.t)
    return spent


def state_at(events, t):
    """The coordinator state at t [s] from the state events ("" before the first)."""
    state = ""
    for e in sorted((e for e in events if e.kind == "state"), key=lambda e: e.t):
        if e.t > t:
            break
        state = e.name
    return state


def _holds_under(samples, i, bound, hold):
    """True if the slot RMS of samples[i] and of every sample up to hold [s] later is under
    bound [m], and the samples reach that far (NaN, no follower measured, is not under)."""
    for j in range(i, len(samples)):
        w = samples[j]
        if w.t > samples[i].t + hold + 1e-9:
            return True
        if not w.slot_rms < bound:
            return False
        if w.t >= samples[i].t + hold - 1e-9:
            return True
    return False


def recoveries(run):
    """One dict per loss: robot, t_s, time_to_degraded_s, recovery_time_s (None: never)."""
    config = run.config
    out = []
    for loss in (e for e in run.events if e.kind == "loss"):
        degraded = None
        if state_at(run.events, loss.t) == "DEGRADED":
            degraded = 0.0
        else:
            later = [e.t for e in run.events if e.kind == "state" and e.name == "DEGRADED" and e.t >= loss.t]
            degraded = min(later) - loss.t if later else None
        recovered = None
        samples = [s for s in run.samples if s.t >= loss.t]
        for i, s in enumerate(samples):
            if _holds_under(samples, i, config.recovered_rms, config.recovered_hold):
                recovered = s.t - loss.t
                break
        out.append({"robot": loss.name, "t_s": loss.t, "time_to_degraded_s": degraded,
                    "recovery_time_s": recovered})
    return out


def leader_speed(before, now):
    """Speed [m/s] of now's leader between two samples; 0 if unknown (no pose, new leader)."""
    leader = now.leader
    if not leader or leader != before.leader or now.t <= before.t \
            or leader not in now.robots or leader not in before.robots:
        return 0.0
    a, b = before.robots[leader], now.robots[leader]
    speed = math.hypot(b.x - a.x, b.y - a.y) / (now.t - before.t)
    return speed if math.isfinite(speed) else 0.0


def _controller_silent(times, t, config):
    """Whether a controller heard at the sorted times has been silent at t for controller_silence
    (one never heard is not: it may not publish at all)."""
    k = bisect.bisect_right(times, t + 1e-9)
    return k > 0 and t - times[k - 1] >= config.controller_silence


def summarize(run):
    """The summary of a Run: a JSON-ready dict (units in the key names, None = no data)."""
    config = run.config
    start, end = run_span(run)
    controller = {r: [] for r in run.robots}
    for c in run.controller:
        controller.setdefault(c.robot, []).append(c)
    robots = {}
    pooled_slot, pooled_fit = [], []
    for r in run.robots:
        track = [s.robots[r] for s in run.samples if r in s.robots]
        slot = [rs.slot_error for rs in track]
        fit = [rs.fit_error for rs in track]
        pooled_slot += slot
        pooled_fit += fit
        entry = {"slot_samples": len(_finite(slot))}
        entry.update(_stats(slot, "slot", "m", rms=True, percentiles=(95,)))
        entry.update(_stats(fit, "fit", "m", rms=True, percentiles=(95,)))
        entry.update(_controller_stats(controller[r]))
        entry["distance_m"] = track[-1].distance if track else 0.0
        entry["energy_j"] = track[-1].energy if track else 0.0
        robots[r] = entry

    # Steady errors: ARRIVED, and NAVIGATING while the leader moves (its speed from this sample
    # and the one before) for the followers whose slots have been free for free_hold and whose
    # controllers are alive. A slot is blocked (slot_free 0) in or beside a wall of the map or a
    # static obstacle of the simulator, spawned ones too (collector.on_obstacles): the follower
    # cannot hold it and drives around.
    heard = {r: sorted(c.t for c in cs) for r, cs in controller.items()}
    navigating, arrived = [], []
    blocked_since = {}   # robot -> time of its slot's newest blocked sample
    moving_samples = blocked_samples = 0
    for i, s in enumerate(run.samples):
        for r, rs in s.robots.items():
            if rs.slot_free == 0.0:
                blocked_since[r] = s.t
        followers = {r: rs for r, rs in s.robots.items()
                     if math.isfinite(rs.slot_error) and not _controller_silent(heard.get(r, ()), s.t, config)}
        if s.state == "ARRIVED":
            arrived += [rs.slot_error for rs in followers.values()]
        elif s.state == "NAVIGATING" and i > 0 and leader_speed(run.samples[i - 1], s) > config.moving_speed:
            for r, rs in followers.items():
                moving_samples += 1
                if s.t - blocked_since.get(r, -math.inf) >= config.free_hold - 1e-9:
                    navigating.append(rs.slot_error)
                if rs.slot_free == 0.0:
                    blocked_samples += 1

    fleet = {"slot_samples": len(_finite(pooled_slot))}
    fleet.update(_stats(pooled_slot, "slot", "m", rms=True, percentiles=(95,)))
    fleet.update(_stats(pooled_fit, "fit", "m", rms=True, percentiles=(95,)))
    fleet["steady_navigating_slot_rms_m"] = finite_rms(navigating)
    fleet["steady_arrived_slot_rms_m"] = finite_rms(arrived)
    fleet["slot_blocked_share"] = blocked_samples / moving_samples if moving_samples else None
    lateral = [s.leader_lateral for s in run.samples if s.state in PLAN_STATES]
    fleet.update(_stats(lateral, "leader_lateral", "m", rms=True))
    fleet.update(_controller_stats(run.controller))
    methods = [e.name for e in run.events if e.kind == "latency_method"]   # how latency was measured
    fleet["latency_method"] = " then ".join(m for k, m in enumerate(methods) if k == 0 or m != methods[k - 1]) or None
    closest = None
    for s in run.samples:
        if math.isfinite(s.min_clearance) and (closest is None or s.min_clearance < closest.min_clearance):
            closest = s
    fleet["min_clearance_m"] = closest.min_clearance if closest else None
    fleet["min_clearance_t_s"] = closest.t if closest else None
    fleet["min_clearance_pair"] = closest.clearance_pair if closest else None
    fleet["distance_m"] = sum(e["distance_m"] for e in robots.values())
    fleet["energy_j"] = sum(e["energy_j"] for e in robots.values())
    contacts = [e for e in run.events if e.kind == "contact"]
    fleet["contacts"] = len(contacts)
    fleet["switches"] = sum(1 for e in run.events if e.kind == "switch")
    fleet["losses"] = sum(1 for e in run.events if e.kind == "loss")
    fleet["rejoins"] = sum(1 for e in run.events if e.kind == "rejoin")
    fleet["time_in_state_s"] = time_in_states(run.events, end)
    return {
        "start_s": start,
        "duration_s": end - start,
        "samples": len(run.samples),
        "state": state_at(run.events, end),
        "fleet": fleet,
        "robots": robots,
        "recoveries": recoveries(run),
        "contact_list": [{"t_s": e.t, "body_a": e.name, "body_b": e.detail, "x_m": e.x, "y_m": e.y}
                         for e in contacts],
        "config": config.to_dict(),
    }
