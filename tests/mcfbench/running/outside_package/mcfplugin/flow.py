"""The cotangent scheme with the consistent P1 mass (Dziuk 1991), numpy and scipy only:
a flow class following :class:`mcfbench.running.flow.SchemeFlow` (state ``X`` (3, n),
``system``, ``advance``, ``defects``, ``frame``), written outside the suite."""

import numpy as np
import scipy.sparse as sp


class ConsistentCotanFlow:
    """``(M/tau + L) X^{n+1} = M X^n / tau``: ``L`` the cotangent stiffness, ``M`` the
    consistent mass (``|T|/12 (1 + delta_ab)`` on each triangle), both at ``X^n``."""

    def __init__(self, vertices, faces, tau):
        self._X = np.array(vertices, dtype=float).T.copy()
        self._faces = np.asarray(faces, dtype=np.int64)
        self.tau, self.n = float(tau), 0
        edges = np.sort(self._faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        unique, count = np.unique(edges, axis=0, return_counts=True)
        self._fixed = np.zeros(self._X.shape[1], dtype=bool)
        self._fixed[unique[count == 1].ravel()] = True

    X = state = property(lambda self: self._X)
    vertices = property(lambda self: self._X.T)
    faces = property(lambda self: self._faces)
    fixed = property(lambda self: self._fixed)

    def _areas(self, X):
        P = X.T[self._faces]
        return 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)

    def _operators(self, X):
        P, F, n = X.T, self._faces, X.shape[1]
        rows, cols, vals = [], [], []
        area = self._areas(X)
        for a in range(3):                      # the angle at corner a, opposite edge (b, c)
            b, c = (a + 1) % 3, (a + 2) % 3
            u, v = P[F[:, b]] - P[F[:, a]], P[F[:, c]] - P[F[:, a]]
            w = 0.5 * np.einsum("ij,ij->i", u, v) / (2.0 * area)
            rows += [F[:, b], F[:, c], F[:, b], F[:, c]]
            cols += [F[:, c], F[:, b], F[:, b], F[:, c]]
            vals += [-w, -w, w, w]
        L = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, n))
        I, J = np.repeat(F, 3, axis=1).ravel(), np.tile(F, (1, 3)).ravel()
        m = (area[:, None] / 12.0 * (1.0 + np.eye(3).ravel()[None, :])).ravel()
        return L, sp.csr_matrix((m, (I, J)), shape=(n, n))

    @property
    def l2_weights(self):
        return np.asarray(self._operators(self._X)[1].sum(axis=1)).ravel()

    def system(self, at=None, base=None, dt=None):
        at = self._X if at is None else at
        base = self._X if base is None else base
        dt = self.tau if dt is None else dt
        L, M = self._operators(at)
        A = (M / dt + L).tolil()
        b = (M @ base.T).T / dt
        for i in np.flatnonzero(self._fixed):
            A.rows[i], A.data[i] = [i], [1.0]
            b[:, i] = base[:, i]
        return A.tocsr(), b

    def advance(self, X):
        self._X = np.array(X, dtype=float)
        self.n += 1

    def defects(self):
        area = self._areas(self._X)
        bad = np.flatnonzero(area <= 1e-14 * area.max())
        return [("degenerated", f"triangle {t}: area {area[t]:.3g}") for t in bad[:1]]

    def frame(self):
        return {"vertices": self._X.T.copy()}
