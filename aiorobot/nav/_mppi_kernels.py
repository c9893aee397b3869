"""Numba kernels of the MPPI controller (cached, GIL released): sampled rollouts, the critics, the update.

Layouts (B = ``batch_size``, T = ``time_steps``): controls and velocities are (3, B, T) float64
with axis 0 = (vx, vy, wz); trajectories are three (B, T) arrays x, y, yaw; ``costs`` is (B,) and
every critic *adds* its share to it, as nav2_mppi_controller's critics add to ``data.costs``.
The arithmetic follows nav2_mppi_controller (``Optimizer``, ``MotionModel::predict``, each
critic's ``score``); the docstrings say where. Every kernel writes into arrays the caller owns,
so a control cycle allocates nothing here.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = [
    "clamp_by_accel",
    "constrain_sequence",
    "constraint_critic",
    "furthest_reached_path_point",
    "goal_angle_critic",
    "goal_critic",
    "obstacle_distances",
    "obstacles_critic",
    "path_align_critic",
    "path_angle_critic",
    "path_follow_critic",
    "prefer_forward_critic",
    "rollout",
    "update_control_sequence",
    "warm_up",
]

#: motion model codes the kernels take (``MotionModel`` in _mppi.py names them)
DIFF_DRIVE, OMNI, ACKERMANN = 0, 1, 2


@numba.njit(cache=True, nogil=True, inline="always")
def _wrap(a):  # pragma: no cover - compiled
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@numba.njit(cache=True, nogil=True, inline="always")
def _add(costs, i, value, weight, power):  # pragma: no cover - compiled
    """``costs[i] += (value * weight) ** power`` as the critics do (power 1: no pow)."""
    if power > 1:
        costs[i] += (value * weight) ** power
    else:
        costs[i] += value * weight


@numba.njit(cache=True, nogil=True)
def rollout(noise, cs, speed, pose, model_dt, accel, holonomic, cv, v, xs, ys, yaws, travelled):  # pragma: no cover - compiled
    """Sample B control sequences around ``cs`` and roll each out from ``pose``.

    ``noise`` (3, B, T), ``cs`` (3, T): the noised controls ``cv = cs + noise`` (Nav2's
    ``setNoisedControls``). Velocities ``v`` (MotionModel::predict): step 0 is the current
    ``speed`` (3,); step i is ``cv[:, i-1]`` clamped to what ``accel`` = (ax_max, ax_min, ay_max,
    ay_min, az_max) allows from step i-1 in ``model_dt`` (ax_min decelerates when moving forward,
    ax_max when moving back). Poses (integrateStateVelocities): yaw_i = yaw0 + sum_{k<=i} wz_k dt,
    positions step with the previous yaw. Non-holonomic models keep vy at zero. ``travelled`` (B,)
    gets each trajectory's length from its first pose to its last (what findPathFurthestReachedPoint
    sums): a step's length is its speed times ``model_dt``.

    The heading's cosine and sine are advanced by rotating them by the step's turn (a 7th-order
    series, exact to ~1e-15 for turns under 0.2 rad; larger turns take cos and sin): twice as fast
    as a cos and a sin per pose (0.37 against 0.74 ms for 1000 x 56 on the 2-core VM).
    """
    _, nb, nt = noise.shape
    max_dvx = model_dt * accel[0]
    min_dvx = model_dt * accel[1]
    max_dvy = model_dt * accel[2]
    min_dvy = model_dt * accel[3]
    max_dwz = model_dt * accel[4]
    x0, y0, th0 = pose[0], pose[1], pose[2]
    for b in range(nb):
        for t in range(nt):
            cv[0, b, t] = cs[0, t] + noise[0, b, t]
            cv[2, b, t] = cs[2, t] + noise[2, b, t]
            cv[1, b, t] = cs[1, t] + noise[1, b, t] if holonomic else 0.0
        vx, vy, wz = speed[0], speed[1] if holonomic else 0.0, speed[2]
        x, y, th = x0, y0, th0
        c, s = math.cos(th), math.sin(th)
        length = 0.0
        for t in range(nt):
            if t > 0:
                if vx > 0.0:
                    lo, hi = vx + min_dvx, vx + max_dvx
                else:
                    lo, hi = vx - max_dvx, vx - min_dvx
                vx = min(max(cv[0, b, t - 1], lo), hi)
                wz = min(max(cv[2, b, t - 1], wz - max_dwz), wz + max_dwz)
                if holonomic:
                    if vy > 0.0:
                        lo, hi = vy + min_dvy, vy + max_dvy
                    else:
                        lo, hi = vy - max_dvy, vy - min_dvy
                    vy = min(max(cv[1, b, t - 1], lo), hi)
            v[0, b, t] = vx
            v[1, b, t] = vy
            v[2, b, t] = wz
            x += (vx * c - vy * s) * model_dt
            y += (vx * s + vy * c) * model_dt
            if t > 0:
                length += math.sqrt(vx * vx + vy * vy) * model_dt
            d = wz * model_dt
            th += d
            if abs(d) < 0.2:
                d2 = d * d
                cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 / 720.0))
                sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 / 5040.0)))
                c, s = c * cd - s * sd, s * cd + c * sd
            else:
                c, s = math.cos(th), math.sin(th)
            xs[b, t] = x
            ys[b, t] = y
            yaws[b, t] = th
        travelled[b] = length


@numba.njit(cache=True, nogil=True)
def clamp_by_accel(last, value, min_delta, max_delta):  # pragma: no cover - compiled
    """utils::clampVelocityByAccel: ``min_delta`` (<= 0) slows a forward speed, ``max_delta`` speeds it up."""
    if last >= 0.0:
        return min(max(value, last + min_delta), last + max_delta)
    return min(max(value, last - max_delta), last - min_delta)


@numba.njit(cache=True, nogil=True)
def constrain_sequence(cs, speed, lo, hi, accel, first_dt, model_dt, holonomic):  # pragma: no cover - compiled
    """Optimizer::applyControlSequenceConstraints' loop: each step of ``cs`` (3, T) clamped to
    [lo, hi] (3,), then to what ``accel`` (ax_max, ax_min, ay_max, ay_min, az_max) allows from the
    step before (from ``speed`` over ``first_dt`` for step 0, ``model_dt`` after)."""
    nt = cs.shape[1]
    last0, last1, last2 = speed[0], speed[1], speed[2]
    dt = first_dt
    for i in range(nt):
        if i == 1:
            dt = model_dt
        v = min(max(cs[0, i], lo[0]), hi[0])
        last0 = cs[0, i] = clamp_by_accel(last0, v, dt * accel[1], dt * accel[0])
        v = min(max(cs[2, i], lo[2]), hi[2])
        last2 = cs[2, i] = clamp_by_accel(last2, v, -dt * accel[4], dt * accel[4])
        if holonomic:
            v = min(max(cs[1, i], lo[1]), hi[1])
            last1 = cs[1, i] = clamp_by_accel(last1, v, dt * accel[3], dt * accel[2])


@numba.njit(cache=True, nogil=True)
def constraint_critic(v, model_dt, vx_max, vx_min, vy_max, model, min_turning_r, weight, power, costs):  # pragma: no cover
    """ConstraintCritic: the time spent (x speed) outside [vx_min, vx_max], |vy| > vy_max (omni),
    or turning tighter than ``min_turning_r`` (Ackermann)."""
    _, nb, nt = v.shape
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            vx = v[0, b, t]
            over = max(vx - vx_max, 0.0) + max(vx_min - vx, 0.0)
            if model == OMNI:
                over += max(abs(v[1, b, t]) - vy_max, 0.0)
            elif model == ACKERMANN:
                over += max(min_turning_r - abs(vx) / max(abs(v[2, b, t]), 1e-6), 0.0)
            acc += over * model_dt
        _add(costs, b, acc, weight, power)


@numba.njit(cache=True, nogil=True)
def goal_critic(xs, ys, gx, gy, weight, power, costs):  # pragma: no cover - compiled
    """GoalCritic: the mean distance of a trajectory's poses to the goal."""
    nb, nt = xs.shape
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            acc += math.hypot(xs[b, t] - gx, ys[b, t] - gy)
        _add(costs, b, acc / nt, weight, power)


@numba.njit(cache=True, nogil=True)
def goal_angle_critic(yaws, gyaw, weight, power, costs):  # pragma: no cover - compiled
    """GoalAngleCritic: the mean |heading error| to the goal's yaw."""
    nb, nt = yaws.shape
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            acc += abs(_wrap(gyaw - yaws[b, t]))
        _add(costs, b, acc / nt, weight, power)


@numba.njit(cache=True, nogil=True)
def prefer_forward_critic(v, model_dt, weight, power, costs):  # pragma: no cover - compiled
    """PreferForwardCritic: the distance a trajectory covers backwards."""
    _, nb, nt = v.shape
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            acc += max(-v[0, b, t], 0.0) * model_dt
        _add(costs, b, acc, weight, power)


@numba.njit(cache=True, nogil=True)
def furthest_reached_path_point(xs, ys, travelled, path, path_dist):  # pragma: no cover - compiled
    """utils::findPathFurthestReachedPoint: for each trajectory, the path point nearest its end
    among those its ``travelled`` distance (B,) could reach; the furthest over the batch."""
    nb, nt = xs.shape
    n = path.shape[0]
    best = 0
    for b in range(nb):
        reach = np.searchsorted(path_dist, travelled[b])  # lower_bound
        reach = min(reach, n - 1)
        ex, ey = xs[b, nt - 1], ys[b, nt - 1]
        arg, dmin = 0, np.inf
        for i in range(reach + 1):
            d = (path[i, 0] - ex) ** 2 + (path[i, 1] - ey) ** 2
            if d < dmin:
                dmin, arg = d, i
        best = max(best, arg)
    return best


@numba.njit(cache=True, nogil=True, inline="always")
def _closest_path_pt(path_dist, dist, init):  # pragma: no cover - compiled
    """utils::findClosestPathPt: the path index whose integrated distance is nearest ``dist``, from ``init`` on."""
    n = path_dist.shape[0]
    prev = path_dist[init] if init != 0 else 0.0
    for i in range(init + 1, n):
        cur = path_dist[i]
        if cur > dist:
            if dist - prev < cur - dist:
                return i - 1
            return i
        prev = cur
    return n - 1


@numba.njit(cache=True, nogil=True)
def path_align_critic(xs, ys, yaws, path, path_dist, valid, segments, step, use_orientations, weight, power, costs):  # pragma: no cover
    """PathAlignCritic: every ``step``-th trajectory pose against the path point as far along the
    path as the trajectory has travelled (valid points of the first ``segments`` only); the mean
    distance (plus the heading error with ``use_orientations``)."""
    nb, nt = xs.shape
    for b in range(nb):
        total, samples, travelled, pt = 0.0, 0, 0.0, 0
        px, py = xs[b, 0], ys[b, 0]
        for t in range(step, nt, step):
            tx, ty = xs[b, t], ys[b, t]
            travelled += math.hypot(tx - px, ty - py)
            px, py = tx, ty
            pt = _closest_path_pt(path_dist[:segments], travelled, pt)
            if valid[pt]:
                dx, dy = path[pt, 0] - tx, path[pt, 1] - ty
                samples += 1
                if use_orientations:
                    dyaw = _wrap(yaws[b, t] - path[pt, 2])
                    total += math.sqrt(dx * dx + dy * dy + dyaw * dyaw)
                else:
                    total += math.sqrt(dx * dx + dy * dy)
        _add(costs, b, total / samples if samples > 0 else 0.0, weight, power)


@numba.njit(cache=True, nogil=True)
def path_follow_critic(xs, ys, tx, ty, weight, power, costs):  # pragma: no cover - compiled
    """PathFollowCritic: the distance from a trajectory's end to the target path point."""
    nb, nt = xs.shape
    for b in range(nb):
        _add(costs, b, math.hypot(xs[b, nt - 1] - tx, ys[b, nt - 1] - ty), weight, power)


@numba.njit(cache=True, nogil=True)
def path_angle_critic(xs, ys, yaws, tx, ty, weight, power, costs):  # pragma: no cover - compiled
    """PathAngleCritic (forward preference): the angle between a trajectory's final heading and
    the direction from its end to the target path point."""
    nb, nt = xs.shape
    for b in range(nb):
        bearing = math.atan2(ty - ys[b, nt - 1], tx - xs[b, nt - 1])
        _add(costs, b, abs(_wrap(bearing - yaws[b, nt - 1])), weight, power)


@numba.njit(cache=True, nogil=True)
def obstacles_critic(xs, ys, grid, origin_x, origin_y, resolution, tracking_unknown, distance, inflation_radius, margin,
                     near_goal, critical_weight, repulsion_weight, collision_cost, power, costs):  # pragma: no cover - compiled
    """ObstaclesCritic (circular robot): a trajectory through a lethal or inscribed cell (or unknown
    when not tracking unknown) costs ``collision_cost``; otherwise the depth inside
    ``collision_margin_distance``, summed. Away from the goal each pose in inflated space also adds
    ``inflation_radius - distance`` (repulsion, batch-min removed and divided by T). The distance
    comes from the cost by inverting the inflation function as Nav2's ``distanceToObstacle`` does:
    ``distance`` (256,) holds it by cost (:func:`obstacle_distances`; NaN: no inflation layer).
    Returns True when every trajectory collides (Nav2's ``fail_flag``)."""
    nb, nt = xs.shape
    h, w = grid.shape
    raw = np.zeros(nb)
    rep = np.zeros(nb)
    all_collide = True
    inv_res = 1.0 / resolution
    for b in range(nb):
        collide = False
        acc = 0.0
        for t in range(nt):
            c = int(math.floor((xs[b, t] - origin_x) * inv_res))
            r = int(math.floor((ys[b, t] - origin_y) * inv_res))
            cost = 255 if (r < 0 or c < 0 or r >= h or c >= w) else int(grid[r, c])
            if cost < 1:
                continue
            if cost == 254 or cost == 253 or (cost == 255 and not tracking_unknown):
                collide = True
                break
            dist = distance[cost]
            if math.isnan(dist):
                continue
            if dist < margin:
                acc += margin - dist
            if not near_goal:
                rep[b] += inflation_radius - dist
        if not collide:
            all_collide = False
        raw[b] = collision_cost if collide else acc
    rmin = rep.min()
    for b in range(nb):
        value = critical_weight * raw[b] + repulsion_weight * (rep[b] - rmin) / nt
        costs[b] += value ** power if power > 1 else value
    return all_collide


def obstacle_distances(inscribed_radius: float, scale_factor: float, inflation_radius: float) -> np.ndarray:
    """ObstaclesCritic::distanceToObstacle for every cost 0..255 (circular robot), NaN for all
    when there is no inflation (``inflation_radius`` or ``cost_scaling_factor`` 0)."""
    if inflation_radius == 0.0 or scale_factor == 0.0:
        return np.full(256, np.nan)
    cost = np.maximum(np.arange(256, dtype=np.float64), 1.0)
    return (scale_factor * inscribed_radius - np.log(cost) + math.log(253.0)) / scale_factor - inscribed_radius


@numba.njit(cache=True, nogil=True)
def update_control_sequence(costs, cv, cs, gamma, std, temperature, holonomic):  # pragma: no cover - compiled
    """Optimizer::updateControlSequence: add the control cost gamma/std^2 * sum_t (cv - cs) * cs to
    ``costs``, weight the samples by softmax(-(costs - min) / temperature) and write the weighted mean
    of ``cv`` into ``cs``. Axes whose ``std`` is 0 (and vy when not holonomic) keep cs unchanged."""
    _, nb, nt = cv.shape
    for a in range(3):
        if std[a] <= 0.0 or (a == 1 and not holonomic):
            continue
        g = gamma / (std[a] * std[a])
        for b in range(nb):
            acc = 0.0
            for t in range(nt):
                acc += (cv[a, b, t] - cs[a, t]) * cs[a, t]
            costs[b] += g * acc
    cmin = costs.min()
    weights = np.exp(-(costs - cmin) / temperature)
    weights /= weights.sum()
    for a in range(3):
        if std[a] <= 0.0 or (a == 1 and not holonomic):
            continue
        for t in range(nt):
            acc = 0.0
            for b in range(nb):
                acc += weights[b] * cv[a, b, t]
            cs[a, t] = acc
    return weights


def warm_up() -> None:
    """Compile (first run) or load every kernel on tiny inputs of the types the controller passes."""
    nb, nt = 2, 3
    noise = np.zeros((3, nb, nt))
    cs = np.zeros((3, nt))
    v, cv = np.zeros((3, nb, nt)), np.zeros((3, nb, nt))
    xs, ys, yaws = np.zeros((nb, nt)), np.zeros((nb, nt)), np.zeros((nb, nt))
    costs = np.zeros(nb)
    path = np.zeros((2, 3))
    path_dist = np.zeros(2)
    valid = np.ones(2, dtype=np.bool_)
    rollout(noise, cs, np.zeros(3), np.zeros(3), 0.05, np.ones(5), True, cv, v, xs, ys, yaws, costs)
    clamp_by_accel(0.0, 0.1, -0.15, 0.15)
    constrain_sequence(cs, np.zeros(3), -np.ones(3), np.ones(3), np.ones(5), 0.05, 0.05, True)
    constraint_critic(v, 0.05, 0.5, -0.35, 0.5, DIFF_DRIVE, 0.2, 4.0, 1, costs)
    goal_critic(xs, ys, 0.0, 0.0, 5.0, 1, costs)
    goal_angle_critic(yaws, 0.0, 3.0, 1, costs)
    prefer_forward_critic(v, 0.05, 5.0, 1, costs)
    furthest_reached_path_point(xs, ys, costs, path, path_dist)
    path_align_critic(xs, ys, yaws, path, path_dist, valid, 2, 1, False, 14.0, 1, costs)
    path_follow_critic(xs, ys, 0.0, 0.0, 5.0, 1, costs)
    path_angle_critic(xs, ys, yaws, 0.0, 0.0, 2.2, 1, costs)
    obstacles_critic(xs, ys, np.zeros((2, 2), dtype=np.uint8), 0.0, 0.0, 0.05, True, obstacle_distances(0.22, 3.0, 0.55),
                     0.55, 0.1, False, 20.0, 1.5, 100000.0, 1, costs)
    update_control_sequence(costs, cv, cs, 0.015, np.ones(3), 0.3, True)
