"""The SLAM pose graph and its sparse least-squares optimiser (pure: numpy + scipy.sparse).

Nodes are robot poses (x, y, yaw) in the map frame. An edge ``i -> j`` holds a measured pose of
``j`` in ``i``'s frame with its information matrix (inverse covariance): odometry and scan
matches between consecutive nodes, loop closures between far-apart ones. :meth:`PoseGraph.optimize`
is Gauss-Newton on the sum of squared Mahalanobis errors (Grisetti et al., "A tutorial on
graph-based SLAM", 2010, section IV), node 0 held fixed, each step one sparse solve; loop-closure
edges carry Dynamic Covariance Scaling (Agarwal et al., ICRA 2013), a robust kernel whose weight
``min(1, 2 phi / (phi + chi2))`` lets a closure that disagrees with everything else fade to
nothing instead of bending the map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["EDGE_KINDS", "OptimizeResult", "PoseGraph", "compose", "relative", "wrap"]

#: edge kinds, by their code in :attr:`PoseGraph.edge_kinds`
EDGE_KINDS = ("odometry", "scan_match", "loop_closure")


def wrap(a: NDArray[np.float64] | float) -> NDArray[np.float64] | float:
    """Angles to (-pi, pi]."""
    return (np.asarray(a) + math.pi) % (2.0 * math.pi) - math.pi if isinstance(a, np.ndarray) else (a + math.pi) % (2.0 * math.pi) - math.pi


def compose(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """a ⊕ b: the pose b (given in a's frame) in a's parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], float(wrap(a[2] + b[2]))


def relative(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """a⁻¹ ⊕ b: the pose b in a's frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return c * dx + s * dy, -s * dx + c * dy, float(wrap(b[2] - a[2]))


@dataclass(frozen=True, slots=True)
class OptimizeResult:
    """What one :meth:`PoseGraph.optimize` did: iterations, chi2 before/after, the loop-closure
    weights it ended with (DCS, 1 = fully trusted) and the wall time it took."""

    iterations: int
    chi2_before: float
    chi2_after: float
    loop_weights: tuple[float, ...]
    wall_sec: float


class PoseGraph:
    """Nodes (N, 3) and edges (i, j, z (3,), information (3, 3), kind); grows by appending."""

    def __init__(self) -> None:
        self.poses = np.zeros((0, 3))
        self.edge_i = np.zeros(0, dtype=np.int64)
        self.edge_j = np.zeros(0, dtype=np.int64)
        self.edge_z = np.zeros((0, 3))
        self.edge_info = np.zeros((0, 3, 3))
        self.edge_kinds = np.zeros(0, dtype=np.int64)

    def __len__(self) -> int:
        return self.poses.shape[0]

    def __repr__(self) -> str:
        counts = ", ".join(f"{name}={int((self.edge_kinds == k).sum())}" for k, name in enumerate(EDGE_KINDS))
        return f"<PoseGraph nodes={len(self)} {counts}>"

    def add_node(self, pose: tuple[float, float, float]) -> int:
        self.poses = np.vstack([self.poses, np.asarray(pose, dtype=np.float64).reshape(1, 3)])
        return len(self) - 1

    def add_edge(self, i: int, j: int, z: tuple[float, float, float], covariance: NDArray[np.float64], kind: str) -> None:
        """Add the measurement ``z`` of node j in node i's frame with its (3, 3) covariance."""
        if not (0 <= i < len(self) and 0 <= j < len(self)) or i == j:
            raise ValueError(f"pose graph edge: expected two different nodes in [0, {len(self)}), found {i} -> {j}")
        cov = np.asarray(covariance, dtype=np.float64).reshape(3, 3)
        if not np.all(np.isfinite(cov)) or np.any(np.linalg.eigvalsh(0.5 * (cov + cov.T)) <= 0):
            raise ValueError(f"pose graph edge {i} -> {j}: expected a positive definite covariance, found {cov.tolist()}")
        self.edge_i = np.append(self.edge_i, i)
        self.edge_j = np.append(self.edge_j, j)
        self.edge_z = np.vstack([self.edge_z, np.asarray(z, dtype=np.float64).reshape(1, 3)])
        self.edge_info = np.concatenate([self.edge_info, np.linalg.inv(cov)[None]])
        self.edge_kinds = np.append(self.edge_kinds, EDGE_KINDS.index(kind))

    def errors(self, poses: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """Per-edge error (M, 3): measured pose of j in i's frame minus z (Grisetti's e_ij)."""
        p = self.poses if poses is None else poses
        xi, xj = p[self.edge_i], p[self.edge_j]
        ci, si = np.cos(xi[:, 2]), np.sin(xi[:, 2])
        dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
        lx, ly = ci * dx + si * dy, -si * dx + ci * dy  # R_i^T (t_j - t_i)
        cz, sz = np.cos(self.edge_z[:, 2]), np.sin(self.edge_z[:, 2])
        ex, ey = lx - self.edge_z[:, 0], ly - self.edge_z[:, 1]
        return np.column_stack([cz * ex + sz * ey, -sz * ex + cz * ey, wrap(xj[:, 2] - xi[:, 2] - self.edge_z[:, 2])])

    def _weights(self, e: NDArray[np.float64], phi: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        chi2 = np.einsum("mi,mij,mj->m", e, self.edge_info, e)
        w = np.ones(len(chi2))
        loop = self.edge_kinds == 2
        w[loop] = np.minimum(1.0, 2.0 * phi / (phi + chi2[loop])) ** 2
        return w, chi2

    def optimize(self, *, iterations: int = 30, tolerance: float = 1e-6, dcs_phi: float = 1.0) -> OptimizeResult:
        """Gauss-Newton with node 0 fixed; updates :attr:`poses` in place.

        The kernel's phi is annealed (graduated non-convexity): it starts at the largest closure
        chi2, where every closure counts nearly fully and a true closure across a long drift can
        pull the chain in, and shrinks tenfold each time the steps settle, down to ``dcs_phi``,
        where a closure the others contradict weighs next to nothing.
        """
        import time

        from scipy.sparse import coo_matrix
        from scipy.sparse.linalg import spsolve

        t0 = time.perf_counter()
        n = len(self)
        e = self.errors()
        w, chi2 = self._weights(e, dcs_phi)
        before = float((w * chi2).sum())
        loops = chi2[self.edge_kinds == 2]
        phi = max(dcs_phi, float(loops.max()) if len(loops) else dcs_phi)
        w, chi2 = self._weights(e, phi)
        it = 0
        if n > 1 and len(self.edge_i):
            ii, jj = self.edge_i, self.edge_j
            m = len(ii)
            rows_b = np.repeat(np.arange(3), 3)
            cols_b = np.tile(np.arange(3), 3)
            # the sparsity pattern is the same every step: block (i, i), (i, j), (j, i), (j, j) of each edge,
            # then the prior on node 0 (fixed: a stiff prior keeps H regular and the anchor where it is)
            pairs = [(ii, ii), (ii, jj), (jj, ii), (jj, jj)]
            rows = np.concatenate([((3 * r)[:, None] + rows_b[None]).ravel() for r, _ in pairs] + [np.arange(3)])
            cols = np.concatenate([((3 * c)[:, None] + cols_b[None]).ravel() for _, c in pairs] + [np.arange(3)])
            anchor = np.full(3, 1e12)
            gi = (3 * ii[:, None] + np.arange(3)[None]).ravel()
            gj = (3 * jj[:, None] + np.arange(3)[None]).ravel()
            for it in range(1, iterations + 1):
                p = self.poses
                xi, xj = p[ii], p[jj]
                ci, si = np.cos(xi[:, 2]), np.sin(xi[:, 2])
                cz, sz = np.cos(self.edge_z[:, 2]), np.sin(self.edge_z[:, 2])
                dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
                # Rz^T Ri^T and Rz^T dRi^T/dtheta (t_j - t_i)
                rzt = np.stack([np.stack([cz, sz], 1), np.stack([-sz, cz], 1)], 1)
                rit = np.stack([np.stack([ci, si], 1), np.stack([-si, ci], 1)], 1)
                rr = np.einsum("mab,mbc->mac", rzt, rit)
                drit_t = np.stack([-si * dx + ci * dy, -ci * dx - si * dy], 1)
                a = np.zeros((m, 3, 3))
                b = np.zeros((m, 3, 3))
                a[:, :2, :2] = -rr
                a[:, :2, 2] = np.einsum("mab,mb->ma", rzt, drit_t)
                a[:, 2, 2] = -1.0
                b[:, :2, :2] = rr
                b[:, 2, 2] = 1.0
                info = self.edge_info * w[:, None, None]
                ai = np.einsum("mba,mbc->mac", a, info)  # A^T Omega
                bi = np.einsum("mba,mbc->mac", b, info)
                data = np.concatenate([(ai @ a).ravel(), (ai @ b).ravel(), (bi @ a).ravel(), (bi @ b).ravel(), anchor])
                h = coo_matrix((data, (rows, cols)), shape=(3 * n, 3 * n)).tocsc()
                g = (np.bincount(gi, (ai @ e[:, :, None]).ravel(), minlength=3 * n)
                     + np.bincount(gj, (bi @ e[:, :, None]).ravel(), minlength=3 * n))
                dx_all = spsolve(h, -g, permc_spec="MMD_AT_PLUS_A")  # H is symmetric
                if not np.all(np.isfinite(dx_all)):
                    break
                self.poses = p + dx_all.reshape(n, 3)
                self.poses[:, 2] = wrap(self.poses[:, 2])
                e = self.errors()
                if np.abs(dx_all).max() < max(tolerance, 1e-3 if phi > dcs_phi else 0.0):
                    if phi <= dcs_phi:
                        w, chi2 = self._weights(e, phi)
                        break
                    phi = max(dcs_phi, phi * 0.1)
                w, chi2 = self._weights(e, phi)
        after = float((w * chi2).sum())
        loop_w = tuple(float(np.sqrt(x)) for x in w[self.edge_kinds == 2])
        return OptimizeResult(it, before, after, loop_w, time.perf_counter() - t0)

    # -- serialisation -----------------------------------------------------------------

    def arrays(self) -> dict[str, NDArray]:
        return {"poses": self.poses, "edge_i": self.edge_i, "edge_j": self.edge_j, "edge_z": self.edge_z,
                "edge_info": self.edge_info, "edge_kinds": self.edge_kinds}

    @classmethod
    def from_arrays(cls, arrays: dict[str, NDArray]) -> PoseGraph:
        g = cls()
        g.poses = np.asarray(arrays["poses"], dtype=np.float64).reshape(-1, 3)
        g.edge_i = np.asarray(arrays["edge_i"], dtype=np.int64)
        g.edge_j = np.asarray(arrays["edge_j"], dtype=np.int64)
        g.edge_z = np.asarray(arrays["edge_z"], dtype=np.float64).reshape(-1, 3)
        g.edge_info = np.asarray(arrays["edge_info"], dtype=np.float64).reshape(-1, 3, 3)
        g.edge_kinds = np.asarray(arrays["edge_kinds"], dtype=np.int64)
        m = len(g.edge_i)
        if not (len(g.edge_j) == m == len(g.edge_z) == len(g.edge_info) == len(g.edge_kinds)):
            raise ValueError(f"pose graph: expected as many edge ends, measurements, informations and kinds, "
                             f"found {len(g.edge_i)}, {len(g.edge_j)}, {len(g.edge_z)}, {len(g.edge_info)}, {len(g.edge_kinds)}")
        if m and (min(g.edge_i.min(), g.edge_j.min()) < 0 or max(g.edge_i.max(), g.edge_j.max()) >= len(g)):
            raise ValueError(f"pose graph: an edge names a node outside [0, {len(g)})")
        return g
