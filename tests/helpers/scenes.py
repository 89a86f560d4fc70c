"""Small scenes and measures that several test modules share."""

import numpy as np
from scipy.spatial import cKDTree

from granular import Scene


def three_in_line(xi, tc=0.0):
    return Scene(
        [[0.3, 0.5], [0.5, 0.5], [0.7, 0.5]],
        [[1, 0], [0, 0], [-1, 0]],
        0.05,
        boundary="walls",
        restitution=xi,
        contact_duration=tc,
    )


def min_distance_ratio(scene, positions):
    """Smallest centre distance over contact distance among all pairs (periodic images
    included), with a k-d tree."""
    lo, L = scene.lower, scene.lengths
    periodic = scene.boundary == "periodic"
    x = np.mod(positions - lo, L) if periodic else positions - lo
    tree = cKDTree(x, boxsize=L if periodic else None)
    pairs = tree.query_pairs(2 * scene.radii.max(), output_type="ndarray")
    if len(pairs) == 0:
        return np.inf
    d = x[pairs[:, 1]] - x[pairs[:, 0]]
    if periodic:
        d -= L * np.round(d / L)
    dist = np.linalg.norm(d, axis=1)
    return float(np.min(dist / (scene.radii[pairs[:, 0]] + scene.radii[pairs[:, 1]])))


def reference_scene(dim, boundary, xi, mixture, n=12):
    """A small scene for comparisons with the O(N^2) reference."""
    radius = 0.08 if dim == 2 else 0.1
    if mixture:
        radius = radius * np.linspace(0.6, 1.2, n)
    return Scene.random(
        n,
        radius,
        dim=dim,
        boundary=boundary,
        restitution=xi,
        mass=(np.asarray(radius) / 0.1) ** dim if mixture else 1.0,
        wall_restitution=0.9 if boundary == "walls" and xi < 1 else 1.0,
        seed=7,
    )


def tracer_scene(n, r, big, dim, boundary, xi, seed):
    """One particle of radius `big` among n of radius r, masses proportional to volume."""
    radii = np.r_[big, np.full(n, r)]
    return Scene.random(
        n + 1, radii, dim=dim, boundary=boundary, restitution=xi, mass=(radii / r) ** dim, seed=seed
    )
