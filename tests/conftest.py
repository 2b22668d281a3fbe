"""Shared meshes for the tests: the generators of :mod:`mcfbench.surfaces`."""

import functools

import pytest

from mcfbench import surfaces
from mcfbench.surfaces import flat_lattice
from mcfbench.surfaces import random_bumpy_sphere as bumpy_sphere

# The tests that import ``cylinder`` from here were written for quads all cut
# along the same diagonal; the positional parameters (around, along, radius,
# half_height = 0.5) are those of mcfbench.surfaces.cylinder.
cylinder = functools.partial(surfaces.cylinder, diagonals="parallel")

__all__ = ["bumpy_sphere", "cylinder", "flat_lattice"]


@pytest.fixture
def bumpy():
    return bumpy_sphere()
