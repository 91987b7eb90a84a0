"""Compiled kernels of the batched eigenvalues (numba; imported only where it is installed).

Every array carries the batch in its last axis, so that one pose is one vector lane: each
loop's innermost level runs over the batch with unit stride, and the compiler turns it into
AVX2 (or AVX-512) instructions on as many poses at once. `analytical.lanes` calls them and
falls back to LAPACK where numba is missing.

- `tridiagonal`: Householder's reduction of symmetric matrices to tridiagonal form, the
  algorithm of LAPACK's ?sytd2 on the lower triangle (H = I - beta v v^T with v = x - alpha e1,
  alpha = -sign(x1) |x|; p = beta A v, w = p - (beta p.v / 2) v, A <- A - v w^T - w v^T),
  4 n^3 / 3 flops a matrix.
- `largest`: the `count` largest eigenvalues of each tridiagonal by bisection on Sturm counts
  (the number of negative pivots of T - x I is the number of eigenvalues below x), from the
  Gershgorin interval down to adjacent doubles: every eigenvalue to the last bit its
  tridiagonal determines (a multiple eigenvalue is found once per copy).
"""
from __future__ import annotations

import numpy as np
from numba import njit

# the bisection stops when its interval is this many units of the last place wide (or after
# MAX_HALVINGS halvings, enough to cross any double's range)
ULPS = 2.0
MAX_HALVINGS = 2100


@njit(cache=True)
def _reflector(a, column, v, beta, d, e, total):  # pragma: no cover - compiled
    """The Householder vector v (rows below `column`) and beta that zero a's column below its
    first subdiagonal entry, which becomes e[column] (alpha); d[column] the diagonal."""
    n, _, lanes = a.shape
    m = column + 1
    total[:] = 0.0
    for i in range(m, n):
        for b in range(lanes):
            v[i, b] = a[i, column, b]
            total[b] += v[i, b] * v[i, b]
    for b in range(lanes):
        x0 = v[m, b]
        norm = np.sqrt(total[b])
        alpha = -norm if x0 >= 0.0 else norm
        e[column, b] = alpha
        d[column, b] = a[column, column, b]
        v[m, b] = x0 - alpha
        vtv = total[b] - x0 * x0 + v[m, b] * v[m, b]
        beta[b] = 2.0 / vtv if vtv > 0.0 else 0.0  # x = 0: nothing to reduce


@njit(cache=True)
def tridiagonal(a, d, e):  # pragma: no cover - compiled
    """Reduce the symmetric matrices a (n, n, B) (lower triangle read, overwritten) to
    tridiagonal form: diagonal d (n, B), off-diagonal e (n - 1, B). Each step's update of the
    trailing matrix and the next step's product with it share one pass over the matrix."""
    n, _, lanes = a.shape
    v, p = np.empty((n, lanes)), np.zeros((n, lanes))
    following, product = np.empty((n, lanes)), np.empty((n, lanes))
    beta, next_beta, total = np.empty(lanes), np.empty(lanes), np.empty(lanes)
    _reflector(a, 0, v, beta, d, e, total)
    for j in range(1, n):  # p = A v on the trailing matrix of step 0
        for b in range(lanes):
            p[j, b] += a[j, j, b] * v[j, b]
        for i in range(j + 1, n):
            for b in range(lanes):
                entry = a[i, j, b]
                p[i, b] += entry * v[j, b]
                p[j, b] += entry * v[i, b]
    for k in range(n - 2):
        m = k + 1
        total[:] = 0.0
        for i in range(m, n):
            for b in range(lanes):
                total[b] += p[i, b] * v[i, b]
        for i in range(m, n):  # w = beta A v - (beta^2 v.A v / 2) v, into p
            for b in range(lanes):
                p[i, b] = beta[b] * (p[i, b] - 0.5 * beta[b] * total[b] * v[i, b])
        for i in range(m, n):  # the pivot column first: the next reflector reads it
            for b in range(lanes):
                a[i, m, b] -= v[i, b] * p[m, b] + p[i, b] * v[m, b]
        last = k == n - 3
        if not last:
            _reflector(a, m, following, next_beta, d, e, total)
            for i in range(m + 1, n):
                for b in range(lanes):
                    product[i, b] = 0.0
        if last:  # the trailing 1 x 1 block
            for b in range(lanes):
                a[n - 1, n - 1, b] -= 2.0 * v[n - 1, b] * p[n - 1, b]
            break
        for j in range(m + 1, n):  # A <- A - v w^T - w v^T, and the next A v, in one pass
            for b in range(lanes):
                entry = a[j, j, b] - 2.0 * v[j, b] * p[j, b]
                a[j, j, b] = entry
                product[j, b] += entry * following[j, b]
            for i in range(j + 1, n):
                for b in range(lanes):
                    entry = a[i, j, b] - (v[i, b] * p[j, b] + p[i, b] * v[j, b])
                    a[i, j, b] = entry
                    product[i, b] += entry * following[j, b]
                    product[j, b] += entry * following[i, b]
        v, following = following, v
        p, product = product, p
        beta, next_beta = next_beta, beta
    for b in range(lanes):
        d[n - 2, b] = a[n - 2, n - 2, b]
        d[n - 1, b] = a[n - 1, n - 1, b]
        e[n - 2, b] = a[n - 1, n - 2, b]


@njit(cache=True)
def largest(d, e, count, out):  # pragma: no cover - compiled
    """The `count` largest eigenvalues of each tridiagonal (d (n, B), e (n - 1, B)),
    descending, into out (count, B)."""
    n, lanes = d.shape
    squares = np.empty((max(n - 1, 1), lanes))
    low = np.empty(lanes)
    high = np.empty(lanes)
    bottom = np.full(lanes, np.inf)
    top = np.full(lanes, -np.inf)
    for i in range(n - 1):
        for b in range(lanes):
            squares[i, b] = e[i, b] * e[i, b]
    for i in range(n):  # Gershgorin
        for b in range(lanes):
            radius = (abs(e[i - 1, b]) if i > 0 else 0.0) + (abs(e[i, b]) if i < n - 1 else 0.0)
            bottom[b] = min(bottom[b], d[i, b] - radius)
            top[b] = max(top[b], d[i, b] + radius)
    pivot = np.empty(lanes)
    below = np.empty(lanes, np.int64)
    middle = np.empty(lanes)
    tiny = 1e-300
    for t in range(count):
        index = n - 1 - t  # ascending index of the eigenvalue sought
        for b in range(lanes):
            low[b] = bottom[b]
            high[b] = top[b]
        for _ in range(MAX_HALVINGS):
            for b in range(lanes):
                middle[b] = 0.5 * (low[b] + high[b])
                pivot[b] = d[0, b] - middle[b]
                below[b] = 1 if pivot[b] < 0.0 else 0
            for i in range(1, n):
                for b in range(lanes):
                    previous = pivot[b] if pivot[b] != 0.0 else tiny
                    pivot[b] = d[i, b] - middle[b] - squares[i - 1, b] / previous
                    below[b] += 1 if pivot[b] < 0.0 else 0
            done = True
            for b in range(lanes):
                if below[b] <= index:
                    low[b] = middle[b]
                else:
                    high[b] = middle[b]
                width = ULPS * 2.220446049250313e-16 * max(abs(low[b]), abs(high[b]))
                if high[b] - low[b] > max(width, 1e-300):
                    done = False
            if done:
                break
        for b in range(lanes):
            out[t, b] = 0.5 * (low[b] + high[b])


@njit(cache=True)
def gather_lower(stack, a):  # pragma: no cover - compiled
    """a[i, j, b] = stack[b, i, j] on the lower triangle (i >= j): matrices one after the other
    into lanes, each (i, j) row of lanes from one cache line of every matrix."""
    lanes, n, _ = stack.shape
    for i in range(n):
        for j in range(i + 1):
            for b in range(lanes):
                a[i, j, b] = stack[b, i, j]


@njit(cache=True)
def cholesky(a, info):  # pragma: no cover - compiled
    """K = L L^T of each lane's symmetric matrix a (n, n, B), lower triangle read and
    overwritten by L (LAPACK's ?potf2, lower); info[b] = j + 1 at the first pivot j that is not
    positive (the lane is then garbage), 0 where the factor exists."""
    n, _, lanes = a.shape
    inverse = np.empty(lanes)
    for j in range(n):
        for b in range(lanes):
            pivot = a[j, j, b]
            if not pivot > 0.0:
                if info[b] == 0:
                    info[b] = j + 1
                pivot = 1.0
            root = np.sqrt(pivot)
            a[j, j, b] = root
            inverse[b] = 1.0 / root
        for i in range(j + 1, n):
            for b in range(lanes):
                a[i, j, b] *= inverse[b]
        for k in range(j + 1, n):
            for i in range(k, n):
                for b in range(lanes):
                    a[i, k, b] -= a[i, j, b] * a[k, j, b]


@njit(cache=True)
def reduce_standard(a, l):  # pragma: no cover - compiled
    """a <- L^-1 a L^-T on each lane's lower triangle, L lower from `cholesky` (LAPACK's ?sygs2,
    itype 1, lower: per column a scaling, a symmetric rank-2 update of the trailing matrix and a
    forward substitution)."""
    n, _, lanes = a.shape
    half = np.empty(lanes)
    inverse = np.empty(lanes)
    for k in range(n):
        for b in range(lanes):
            diagonal = l[k, k, b]
            entry = a[k, k, b] / (diagonal * diagonal)
            a[k, k, b] = entry
            half[b] = -0.5 * entry
            inverse[b] = 1.0 / diagonal
        if k == n - 1:
            break
        for i in range(k + 1, n):
            for b in range(lanes):
                a[i, k, b] = a[i, k, b] * inverse[b] + half[b] * l[i, k, b]
        for j in range(k + 1, n):
            for i in range(j, n):
                for b in range(lanes):
                    a[i, j, b] -= a[i, k, b] * l[j, k, b] + l[i, k, b] * a[j, k, b]
        for i in range(k + 1, n):
            for b in range(lanes):
                a[i, k, b] += half[b] * l[i, k, b]
        for j in range(k + 1, n):  # solve L[k+1:, k+1:] x = a[k+1:, k], forward
            for b in range(lanes):
                a[j, k, b] /= l[j, j, b]
            for i in range(j + 1, n):
                for b in range(lanes):
                    a[i, k, b] -= a[j, k, b] * l[i, j, b]
