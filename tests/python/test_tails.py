"""compute_weights(tails=...): a leaf's tail is where its bone ends. An arm holds a sword
that points down and back from the hand, apart from the arm: with the hand's tail at the
sword's tip the hand's bone runs inside the sword, which moves with the hand; without it the
hand's bone runs on past the hand along the forearm (by half the forearm), the sword holds
no bone and moves with the forearm, the nearest bone to every point of it."""

import numpy as np

import atlas_skin

# The arm along +x (glTF's axes): shoulder, elbow and hand joints, the hand a leaf.
JOINTS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
PARENTS = np.array([-1, 0, 1])
UPPERARM, FOREARM, HAND = 0, 1, 2
# The hand's tail: down (-y) and back towards the elbow, the sword's tip.
TAIL = np.array([1.5, -1.2, 0.0])


def tube(x0, x1, radius, rings, sides=16):
    """A closed tube along x from x0 to x1: `rings` rings of `sides` vertices, each end capped
    by a fan around a centre vertex; triangles wound outward."""
    positions, faces = [], []
    for k in range(rings):
        x = x0 + (x1 - x0) * k / (rings - 1)
        angles = 2 * np.pi * np.arange(sides) / sides
        positions += [[x, radius * np.cos(a), radius * np.sin(a)] for a in angles]
    for k in range(rings - 1):
        for s in range(sides):
            a, b = k * sides + s, k * sides + (s + 1) % sides
            faces += [[a, b, a + sides], [b, b + sides, a + sides]]
    first, last = len(positions), len(positions) + 1
    positions += [[x0, 0.0, 0.0], [x1, 0.0, 0.0]]
    end = (rings - 1) * sides
    for s in range(sides):
        faces += [[first, (s + 1) % sides, s], [last, end + s, end + (s + 1) % sides]]
    return np.array(positions), np.array(faces)


def bar(start, end, half_width):
    """A closed box of 8 vertices and 12 outward triangles around the segment start→end
    (which lies in the xy plane), 2 × half_width thick."""
    along = end - start
    across = np.array([-along[1], along[0], 0.0]) / np.linalg.norm(along) * half_width
    depth = np.array([0.0, 0.0, half_width])
    corners = [start + i * along + j * across + k * depth
               for i in (0, 1) for j in (-1, 1) for k in (-1, 1)]
    faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
             [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return np.array(corners), np.array(faces)


def arm_with_sword():
    """(positions, triangles, sword's first vertex): a tube of radius 0.15 from x = -0.2 to
    2.5 (rings every 0.1), and a bar 0.1 thick along the hand's tail from 30% of the way
    (about 0.2 below the arm) to the tail."""
    arm, arm_faces = tube(-0.2, 2.5, 0.15, rings=28)
    hand = JOINTS[HAND]
    sword, sword_faces = bar(hand + 0.3 * (TAIL - hand), TAIL, 0.05)
    positions = np.vstack([arm, sword])
    return positions, np.vstack([arm_faces, sword_faces + len(arm)]), len(arm)


def dense_weights(tails):
    positions, triangles, _ = arm_with_sword()
    indices, weights, _ = atlas_skin.compute_weights(
        positions, triangles, JOINTS, PARENTS, tails=tails
    )
    dense = np.zeros((len(positions), len(JOINTS)))
    np.add.at(dense, (np.arange(len(positions))[:, None], indices), weights)
    return dense


def test_the_hands_tail_takes_the_sword_to_the_hand():
    _, _, first = arm_with_sword()
    tails = np.full((len(JOINTS), 3), np.nan)  # NaN rows: no tail (the elbow and shoulder)
    tails[HAND] = TAIL
    with_tails = dense_weights(tails)
    heads_only = dense_weights(None)
    for weights in (with_tails, heads_only):
        assert np.abs(weights.sum(axis=1) - 1).max() < 1e-5
        assert weights.min() >= 0
    assert with_tails[first:, HAND].min() >= 0.99, with_tails[first:]
    assert heads_only[first:, FOREARM].min() >= 0.99, heads_only[first:]
    # The tail moves the hand's bone only: the arm's weights are the same both ways.
    assert np.abs(with_tails[:first] - heads_only[:first]).max() <= 1e-6
