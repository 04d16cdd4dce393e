"""Noisy and clustered cases written to files, answered by manapprox (the authors' Python
code, github.com/aizeny/manapprox), for `examples/noisy_beside_manapprox.rs` to answer
the same files and print both side by side. A measuring instrument only:

    python3 -m venv /tmp/peers && /tmp/peers/bin/pip install numpy scipy
    git clone https://github.com/aizeny/manapprox /tmp/manapprox
    PYTHONPATH=/tmp/manapprox /tmp/peers/bin/python \
        crates/manifold/peers/noisy_cases.py /tmp/noisy [--quick]
    cargo run --release -p umls-manifold --example noisy_beside_manapprox -- /tmp/noisy

Each case directory holds `samples.txt` (noisy position, noisy value per line),
`queries.txt` (clean position, true value, true normal distance 0) and `manapprox.txt`
(value, projection, seconds per query). Cases:
- swiss roll (t cos t, y, t sin t), t ∈ [1.5π, 4.5π], y ∈ [0, 21], f = sin t + cos(y/3);
- S² with f = sin 2x + yz;
  both uniformly random, Gaussian noise s on every coordinate and on the values,
  s ∈ {0.05, 0.1, 0.2}, N ∈ {4k, 16k, 64k}, m ∈ {1, 2};
- the clustered cap: S² with half of the samples in a cap of 5 % of the area, s = 0.01,
  queries on the cap's rim.
"""
import os
import sys
import time

import numpy as np

# manapprox predates NumPy 1.24, which removed these aliases.
np.float = float
np.int = int
import manapprox  # noqa: E402

QUERIES = 200


def swiss(count, rng):
    t = 1.5 * np.pi * (1.0 + 2.0 * rng.random(count))
    y = 21.0 * rng.random(count)
    return np.stack([t * np.cos(t), y, t * np.sin(t)], axis=1), np.sin(t) + np.cos(y / 3.0)


def swiss_queries(count, rng):
    # Away from the roll's edges, where a one-sided neighbourhood is another question.
    t = 1.5 * np.pi * (1.0 + 2.0 * (0.1 + 0.8 * rng.random(count)))
    y = 21.0 * (0.1 + 0.8 * rng.random(count))
    return np.stack([t * np.cos(t), y, t * np.sin(t)], axis=1), np.sin(t) + np.cos(y / 3.0)


def sphere_points(count, rng):
    p = rng.standard_normal((count, 3))
    return p / np.linalg.norm(p, axis=1)[:, None]


def sphere_function(p):
    return np.sin(2.0 * p[:, 0]) + p[:, 1] * p[:, 2]


def cap_points(count, rng, cos_cap):
    # Uniform on the cap z ≥ cos_cap.
    z = cos_cap + (1.0 - cos_cap) * rng.random(count)
    phi = 2.0 * np.pi * rng.random(count)
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def write(path, rows):
    np.savetxt(path, rows, fmt="%.17g")


def answer(directory, samples, values, queries, degree):
    ma = manapprox.ManApproxF(samples.T.copy(), values.copy())
    ma.manifold_dim = 2
    ma.poly_deg = degree
    ma.calculateSigma()
    ma.createTree()
    rows = []
    for r in queries:
        start = time.perf_counter()
        try:
            projection, value = ma.approximateAtPoints(r, flag_project=True)
            rows.append([float(np.ravel(value)[0]), *np.ravel(projection), time.perf_counter() - start])
        except Exception:  # noqa: BLE001 - a failure is a row of NaN, counted by the reader
            rows.append([np.nan] * 4 + [time.perf_counter() - start])
    write(os.path.join(directory, "manapprox.txt"), np.array(rows))


def case(root, name, samples, values, queries, truth, degree):
    directory = os.path.join(root, name)
    os.makedirs(directory, exist_ok=True)
    write(os.path.join(directory, "samples.txt"), np.column_stack([samples, values]))
    write(os.path.join(directory, "queries.txt"), np.column_stack([queries, truth]))
    with open(os.path.join(directory, "degree.txt"), "w") as f:
        f.write(f"{degree}\n")
    answer(directory, samples, values, queries, degree)
    print(name, flush=True)


def main():
    root = sys.argv[1]
    quick = "--quick" in sys.argv
    counts = [4000, 16000] if quick else [4000, 16000, 64000]
    noises = [0.1] if quick else [0.05, 0.1, 0.2]
    for shape in ["swiss", "sphere"]:
        for noise in noises:
            for count in counts:
                rng = np.random.default_rng(1000 * count + int(100 * noise) + (shape == "sphere"))
                if shape == "swiss":
                    clean, f = swiss(count, rng)
                    queries, truth = swiss_queries(QUERIES, rng)
                else:
                    clean = sphere_points(count, rng)
                    f = sphere_function(clean)
                    queries = sphere_points(QUERIES, rng)
                    truth = sphere_function(queries)
                samples = clean + noise * rng.standard_normal(clean.shape)
                values = f + noise * rng.standard_normal(count)
                for degree in [1, 2]:
                    name = f"{shape}-s{noise}-n{count}-m{degree}"
                    case(root, name, samples, values, queries, truth, degree)
    # The clustered cap: half of 8000 samples uniform, half in a cap of 5 % of the area
    # (z ≥ 0.9), s = 0.01; queries on the cap's rim z = 0.9.
    rng = np.random.default_rng(5)
    clean = np.vstack([sphere_points(4000, rng), cap_points(4000, rng, 0.9)])
    f = sphere_function(clean)
    samples = clean + 0.01 * rng.standard_normal(clean.shape)
    values = f + 0.01 * rng.standard_normal(len(clean))
    phi = 2.0 * np.pi * rng.random(QUERIES)
    rim = np.sqrt(1.0 - 0.81)
    queries = np.stack([rim * np.cos(phi), rim * np.sin(phi), np.full(QUERIES, 0.9)], axis=1)
    for degree in [1, 2]:
        case(root, f"cap-s0.01-n8000-m{degree}", samples, values, queries, sphere_function(queries), degree)


if __name__ == "__main__":
    main()
