#!/usr/bin/env python3
"""How evenly adaptive rounds cover an edge pixel (docs/adaptive-sampling.md).

A pixel crossed by a straight edge (value 1 on one side, 0 on the other) at a random angle
and offset; its mean is estimated from the samples a pixel that reaches the cap of 64 holds
besides its four corners: 60 points inside it. Two ways of placing them:

- rounds:   four rounds of 4, 8, 16 and 32 samples, each a jittered lattice of its own
            (how adaptive rounds were taken before the sequence);
- sequence: points [4, 64) of the pixel's scrambled (0,2)-sequence, with the formulas of
            engine/render/sampling.h (sequence_sample), re-implemented here in 32-bit
            integer arithmetic.

Prints the RMSE of each over the edges (deterministic: a fixed seed).

    /usr/bin/python3 scripts/sequence_edge_sim.py [--edges 300] [--seed 1]
"""
import argparse
import math

import numpy as np

M32 = 0xFFFFFFFF


def hash32(x):
    x &= M32
    x ^= x >> 16
    x = (x * 0x7FEB352D) & M32
    x ^= x >> 15
    x = (x * 0x846CA68B) & M32
    return x ^ (x >> 16)


def reverse_bits(x):
    return int(f"{x & M32:032b}"[::-1], 2)


def nested_scramble_reversed(x, seed):
    x = (x + seed) & M32
    for c in (0x6C50B47C, 0xB82F1E52, 0xC7AFE638, 0x8D22F6E6):
        x ^= (x * c) & M32
    return x


def sobol_second_dimension(i):
    y, v = 0, 1 << 31
    while i:
        if i & 1:
            y ^= v
        i >>= 1
        v ^= v >> 1
    return y


def sequence_sample(pixel, index):
    seed_x = hash32(pixel * 0x2545F491 + 0x9E3779B9)
    seed_y = hash32(seed_x ^ 0x6A09E667)
    x = reverse_bits(nested_scramble_reversed(index, seed_x))
    y = reverse_bits(nested_scramble_reversed(reverse_bits(sobol_second_dimension(index)), seed_y))
    return (x >> 8) * 2.0**-24, (y >> 8) * 2.0**-24


def lattice_round(n, rng):
    cols = math.ceil(math.sqrt(n))
    while n % cols:
        cols += 1
    rows = n // cols
    j = np.arange(n)
    return np.stack([(j % cols + rng.random(n)) / cols, (j // cols + rng.random(n)) / rows], 1)


def edge(points, angle, offset):
    return (np.cos(angle) * (points[:, 0] - 0.5) + np.sin(angle) * (points[:, 1] - 0.5) < offset).astype(float)


def covered_fraction(angle, offset, n=1000):
    g = (np.arange(n) + 0.5) / n
    x, y = np.meshgrid(g, g)
    return edge(np.stack([x.ravel(), y.ravel()], 1), angle, offset).mean()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--edges", type=int, default=300)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    err_rounds, err_sequence = [], []
    for pixel in range(a.edges):
        angle, offset = rng.random() * 2 * math.pi, (rng.random() - 0.5) * 0.8
        truth = covered_fraction(angle, offset)
        rounds = np.concatenate([lattice_round(n, rng) for n in (4, 8, 16, 32)])
        err_rounds.append((edge(rounds, angle, offset).mean() - truth) ** 2)
        seq = np.array([sequence_sample(pixel, k) for k in range(4, 64)])
        err_sequence.append((edge(seq, angle, offset).mean() - truth) ** 2)
    print(f"edge pixel, 60 samples, {a.edges} edges (seed {a.seed}): RMSE of the mean")
    print(f"  four rounds, each on its own jittered lattice: {math.sqrt(np.mean(err_rounds)):.4f}")
    print(f"  the pixel's scrambled (0,2)-sequence, points [4, 64): {math.sqrt(np.mean(err_sequence)):.4f}")


if __name__ == "__main__":
    main()
