"""Shared meshes for the tests."""

import numpy as np
import pytest

from ddfv.surfaces import icosphere


def bumpy_sphere(level=2, amplitude=0.15, seed=0):
    """Icosphere with a smooth, non-symmetric radial bump field."""
    V, F = icosphere(level)
    rng = np.random.default_rng(seed)
    k = rng.normal(size=(3, 3))
    r = 1.0 + amplitude * np.sin(V @ k[0]) * np.cos(V @ k[1] + 0.3)
    return V * r[:, None], F


def flat_lattice(m=6, k=5):
    """Unit squares split by their (0,0)-(1,1) diagonal, in the plane z = 0."""
    x, y = np.meshgrid(np.arange(m + 1.0), np.arange(k + 1.0), indexing="xy")
    V = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    i, j = np.meshgrid(np.arange(m), np.arange(k), indexing="xy")
    p = (j * (m + 1) + i).ravel()
    q, r, s = p + 1, p + m + 1, p + m + 2
    F = np.concatenate([np.column_stack([p, q, s]), np.column_stack([p, s, r])])
    return V, F


def cylinder(m=24, k=8, radius=1.0, half_height=0.5):
    """Open cylinder of m x k quads split into triangles, outward oriented."""
    theta = 2 * np.pi * np.arange(m) / m
    z = np.linspace(-half_height, half_height, k + 1)
    V = np.column_stack([np.tile(radius * np.cos(theta), k + 1),
                         np.tile(radius * np.sin(theta), k + 1),
                         np.repeat(z, m)])
    i, j = np.meshgrid(np.arange(m), np.arange(k), indexing="xy")
    p = (j * m + i).ravel()
    q = (j * m + (i + 1) % m).ravel()
    F = np.concatenate([np.column_stack([p, q, q + m]), np.column_stack([p, q + m, p + m])])
    return V, F


@pytest.fixture
def bumpy():
    return bumpy_sphere()
