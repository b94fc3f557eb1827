#!/usr/bin/env python3
"""What one linear system per step gives up on the rigid part of the tumbling bar (BENCHMARKS.md section 31).

phlex's floating step solves the implicit midpoint stage by Newton, two iterations at the tests' accuracy (section 29).
This script asks whether the rigid motion alone explains that, and how schemes with one linear system per step (linear
in the new state) keep the invariants the full-inertia tests watch. The rigid part of options/floating_tumbling.yaml:
the bar 1.0 x 0.1 x 0.1 m, steel (78 kg), its body frame at P, the centroid of the face x = 0, the centre of mass at
c = (0.5, 0, 0) m from P; body rate w = (1, 2, 30) rad/s, v_P = -w x c (centre of mass at rest); dt = 2e-4 s.

In the body frame, with the momenta m = (p, l) = M6 (v_P, w) (M6 = [[m I, -m [c]x], [m [c]x, I_P]], the paper's mass
operator (eq:mass_op) for a rigid body), the Lie-Poisson equations are
    p' = p x w,    l' = l x w + p x v_P,    i.e. m' = J(m) M6^{-1} m,  J(m) = [[0, [p]x], [[p]x, [l]x]] skew;
the energy H = 1/2 m . M6^{-1} m and the Casimirs |p|^2 and p . l (the spatial momenta's invariants) are all quadratic.
The bar's centre of mass is at rest (p = 0, which every scheme below keeps exactly), so the angular momentum's length
|l| = |L| is then a Casimir too.

  midpoint              (m1 - m0)/dt = J(mm) M6^{-1} mm, mm = (m0 + m1)/2, Newton to round-off (phlex's stage):
                        keeps every quadratic invariant
  midpoint, one Newton  the same, one Newton iteration from m0 (section 29's PHLEX_DEBUG_ONE_NEWTON)
  energy-exact          (m1 - m0)/dt = J(me) M6^{-1} mm, me = (3 m0 - m_-1)/2: H exact, the Casimirs not
  Casimir-exact         (m1 - m0)/dt = J(mm) M6^{-1} me: the Casimirs exact (here |l|), H not
  Kahan                 (m1 - m0)/dt = (f(m0, m1) + f(m1, m0))/2, f(a, b) = J(a) M6^{-1} b (Kahan-Hirota-Kimura,
                        polarised): modified invariants kept, H and the Casimirs to O(dt^2)

Prints the largest relative deviation of H and |l| over the run against the bounds of the test
floating_full_long (energy 4e-10, momenta 5e-10; phlex's full flexible step over its one revolution: energy
3.0e-10, P 2.9e-10, L 1.7e-10).

usage: python3 bench/rigid_one_solve.py [--steps 10000] [--dt 2e-4] [--rate 1,2,30]
"""
import argparse
import math

# small vectors and matrices as lists: no numpy needed


def cross(x, y):
    return [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]


def dot(x, y):
    return sum(a * b for a, b in zip(x, y))


def matvec(A, x):
    return [dot(row, x) for row in A]


def solve(A, b):
    """A^{-1} b by Gaussian elimination with partial pivoting"""
    n = len(b)
    M = [A[i][:] + [b[i]] for i in range(n)]
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(M[i][k]))
        M[k], M[p] = M[p], M[k]
        for i in range(k + 1, n):
            f = M[i][k] / M[k][k]
            M[i] = [M[i][j] - f * M[k][j] for j in range(n + 1)]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (M[i][n] - sum(M[i][j] * x[j] for j in range(i + 1, n))) / M[i][i]
    return x


UNIT = [[1.0 if k == j else 0.0 for k in range(6)] for j in range(6)]  # the unit momenta


def identity_minus(cols, h):
    """I - h A, A given by its columns"""
    return [[(1.0 if i == j else 0.0) - h * cols[j][i] for j in range(6)] for i in range(6)]


def cross_matrix(x):
    return [[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]]


def bar():
    """M6 of the bar about P (SI), and the centre of mass c"""
    a, b, h, rho = 1.0, 0.1, 0.1, 7800.0
    m = rho * a * b * h
    c = [0.5 * a, 0.0, 0.0]
    Ic = [m * (b * b + h * h) / 12.0, m * (a * a + h * h) / 12.0, m * (a * a + b * b) / 12.0]
    C = cross_matrix(c)
    # I_P = I_c + m ([c]x)^T [c]x
    IP = [[(Ic[i] if i == j else 0.0) + m * sum(C[k][i] * C[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    M6 = [[0.0] * 6 for _ in range(6)]
    for i in range(3):
        M6[i][i] = m
        for j in range(3):
            M6[i][3 + j] = -m * C[i][j]
            M6[3 + i][j] = m * C[i][j]
            M6[3 + i][3 + j] = IP[i][j]
    return M6, c


def J(mv):
    """the Lie-Poisson structure at the momenta mv = (p, l), a 6 x 6 skew matrix acting on (v_P, w)"""
    P, L = cross_matrix(mv[:3]), cross_matrix(mv[3:])
    return [[0.0] * 3 + P[i] for i in range(3)] + [P[i] + L[i] for i in range(3)]


def step(scheme, m0, mprev, dt, M6inv):
    """m1 from m0 (and the step before, mprev, for the extrapolating schemes); each scheme but the converged midpoint
    solves one 6 x 6 linear system"""
    x = lambda mv: matvec(M6inv, mv)  # (v_P, w) = M6^{-1} m
    if scheme in ("midpoint", "midpoint, one Newton"):
        m1 = m0[:]
        for _ in range(50):
            mm = [(a + b) / 2 for a, b in zip(m0, m1)]
            r = [a - b - dt * c for a, b, c in zip(m1, m0, matvec(J(mm), x(mm)))]
            # d/dm1 of J(mm) M6^{-1} mm = 1/2 (J(mm) M6^{-1} + dJ/dm (M6^{-1} mm)); J(m) y is linear in m: columns by
            # unit momenta
            y = x(mm)
            cols = [[a + b for a, b in zip(matvec(J(mm), x(UNIT[j])), matvec(J(UNIT[j]), y))] for j in range(6)]
            d = solve(identity_minus(cols, 0.5 * dt), [-v for v in r])
            m1 = [a + b for a, b in zip(m1, d)]
            if scheme == "midpoint, one Newton" or math.sqrt(dot(d, d)) <= 1e-16 * math.sqrt(dot(m1, m1)):
                break
        return m1
    # the linearly implicit schemes: (I - dt/2 A) m1 = b, A and b from the known states
    if scheme == "Kahan":  # (m1 - m0)/dt = (J(m0) M6^{-1} m1 + J(m1) M6^{-1} m0)/2
        y0 = x(m0)
        cols = [[a + b for a, b in zip(matvec(J(m0), x(UNIT[j])), matvec(J(UNIT[j]), y0))] for j in range(6)]
        return solve(identity_minus(cols, 0.5 * dt), m0)
    me = [1.5 * a - 0.5 * b for a, b in zip(m0, mprev)]
    if scheme == "energy-exact":  # (m1 - m0)/dt = J(me) M6^{-1} (m0 + m1)/2
        cols = [matvec(J(me), x(UNIT[j])) for j in range(6)]
    elif scheme == "Casimir-exact":  # (m1 - m0)/dt = J((m0 + m1)/2) M6^{-1} me
        ye = x(me)
        cols = [matvec(J(UNIT[j]), ye) for j in range(6)]
    else:
        raise ValueError(scheme)
    rhs = [a + 0.5 * dt * sum(cols[j][i] * m0[j] for j in range(6)) for i, a in enumerate(m0)]
    return solve(identity_minus(cols, 0.5 * dt), rhs)


def invariants(mv, M6inv):
    return 0.5 * dot(mv, matvec(M6inv, mv)), math.sqrt(dot(mv[3:], mv[3:]))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--steps", type=int, default=10000)
    p.add_argument("--dt", type=float, default=2e-4)
    p.add_argument("--rate", default="1,2,30", help="body rate w0 (rad/s); v_P = -w0 x c")
    a = p.parse_args()
    M6, c = bar()
    cols = [solve(M6, UNIT[j]) for j in range(6)]
    M6inv = [[cols[j][i] for j in range(6)] for i in range(6)]
    w0 = [float(v) for v in a.rate.split(",")]
    m0 = matvec(M6, [-v for v in cross(w0, c)] + w0)
    H0, l0 = invariants(m0, M6inv)
    print("tumbling bar, rigid part about P: w0 = %s rad/s, dt = %g s (|w| dt = %.1e), %d steps" % (a.rate, a.dt, math.sqrt(dot(w0, w0)) * a.dt, a.steps))
    print("%-22s %12s %12s %12s" % ("scheme", "max|dH|/H0", "max|d|l||/|l0|", "max|p|/|l0|"))
    for scheme in ["midpoint", "midpoint, one Newton", "energy-exact", "Casimir-exact", "Kahan"]:
        m, mprev = m0[:], None
        eH = el = ep = 0.0
        for _ in range(a.steps):
            # the extrapolating schemes start with one converged midpoint step
            first = mprev is None and scheme in ("energy-exact", "Casimir-exact")
            m, mprev = step("midpoint" if first else scheme, m, mprev, a.dt, M6inv), m
            H, ln = invariants(m, M6inv)
            eH, el, ep = max(eH, abs(H - H0) / H0), max(el, abs(ln - l0) / l0), max(ep, math.sqrt(dot(m[:3], m[:3])) / l0)
        print("%-22s %12.2e %14.2e %12.2e" % (scheme, eH, el, ep))
    print("%-22s %12.2e %14.2e" % ("bounds (tests)", 4e-10, 5e-10))


if __name__ == "__main__":
    main()
