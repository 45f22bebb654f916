"""Print the torus-knot errors of Wang et al. (2008), Tables III/IV, as spinal measures them.

Reference: scipy DOP853 on r' = (x'×x''/|x'|²) × r, rtol 1e-13; torus knot on [0, 2π] with
r0 = N(0) = (-1, 0, 0); error = max angle between r_i and the reference (rad).

    python benchmarks/accuracy_frames.py
"""

import numpy as np
from scipy.integrate import solve_ivp

import spinal
from spinal.curves import TorusKnot


def main():
    k = TorusKnot()
    u_ref = np.linspace(0, 2 * np.pi, 2**11 + 1)

    def rhs(s, r):
        d1, d2 = k.d1(s)[0], k.d2(s)[0]
        return np.cross(np.cross(d1, d2) / d1.dot(d1), r)

    ref = solve_ivp(rhs, (0, 2 * np.pi), [-1.0, 0, 0], method="DOP853", t_eval=u_ref,
                    rtol=1e-13, atol=1e-15).y.T
    print("| segments | double_reflection | rk4 | rk4_phi | rotation | projection |")
    print("|---|---|---|---|---|---|")
    for e in range(6, 12):
        step = 2 ** (11 - e)
        u = u_ref[::step]
        row = []
        for m in ("double_reflection", "rk4", "rk4_phi", "rotation", "projection"):
            F = (spinal.frames(k, u=u, method=m, initial=[-1.0, 0, 0]) if m.startswith("rk4") else
                 spinal.frames(k.point(u), k.d1(u), method=m, initial=[-1.0, 0, 0]))
            r = F[:, :, 0]
            err = np.arctan2(np.linalg.norm(np.cross(r, ref[::step]), axis=1),
                             np.einsum("ij,ij->i", r, ref[::step])).max()
            row.append(f"{err:.4e}")
        print(f"| 2^{e} | " + " | ".join(row) + " |")
    for name, x in [("torus knot", k.sample(4097))]:
        print(f"closing angle, {name}, 4096 segments: {spinal.closing_angle(x):+.10f} rad")


if __name__ == "__main__":
    main()
