"""Per-query time of manapprox (the authors' Python code, github.com/aizeny/manapprox) on
the manifold crate's benchmark case: 4000 Fibonacci samples of S² isometrically embedded
in Rⁿ, f = xy + z, degree 2, 64 queries. A measuring instrument only:

    python3 -m venv /tmp/peers && /tmp/peers/bin/pip install numpy scipy scikit-learn
    git clone https://github.com/aizeny/manapprox /tmp/manapprox
    PYTHONPATH=/tmp/manapprox /tmp/peers/bin/python crates/manifold/peers/manapprox_timing.py
"""
import sys
import time

import numpy as np

# manapprox predates NumPy 1.24, which removed these aliases.
np.float = float
np.int = int
import manapprox  # noqa: E402


def fibonacci(count):
    golden = np.pi * (3.0 - np.sqrt(5.0))
    i = np.arange(count)
    z = 1.0 - 2.0 * (i + 0.5) / count
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(golden * i), r * np.sin(golden * i), z], axis=1)


def main():
    rng = np.random.default_rng(17)
    for n in [int(a) for a in (sys.argv[1:] or ["3", "100", "1000"])]:
        q, _ = np.linalg.qr(rng.standard_normal((n, 3)))
        base = fibonacci(4000)
        probe = fibonacci(64)
        data = (base @ q.T).T  # n × N, manapprox's layout
        values = base[:, 0] * base[:, 1] + base[:, 2]
        ma = manapprox.ManApproxF(data, values)
        ma.manifold_dim = 2
        ma.poly_deg = 2
        ma.calculateSigma()
        ma.createTree()
        queries = probe @ q.T
        start = time.perf_counter()
        for r in queries:
            ma.approximateAtPoints(r)
        elapsed = (time.perf_counter() - start) / len(queries)
        print(f"n = {n}: manapprox {elapsed * 1e3:.3f} ms per query")


if __name__ == "__main__":
    main()
