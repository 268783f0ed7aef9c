/* rotation_methods.c - the rotation integrators of lib/rotation.c side by
 * side on a torque-free box (half extents 0.5, 0.25, 0.1 m, 1 kg) spun at
 * 10 rad/s about each principal axis (0.01 rad/s on the others): relative
 * drift of kinetic energy and of world angular momentum after 20 s, and the
 * largest angle of the body axis from the spin axis. Run: build/bench/rotation_methods [h] */
#include <stdio.h>
#include <stdlib.h>
#include "rotation.h"

int main(int argc, char **argv)
{
    double h = argc > 1 ? atof(argv[1]) : 1.0 / 240.0;
    const double hx = 0.5, hy = 0.25, hz = 0.1, m = 1.0;
    vec3 inertia = v3(m * (hy * hy + hz * hz) / 3, m * (hx * hx + hz * hz) / 3, m * (hx * hx + hy * hy) / 3);
    static const char *names[4] = {"carry L", "implicit gyro", "splitting (DLM)", "midpoint"};
    static const char *axes[3] = {"minor x", "intermediate y", "major z"};
    printf("h = %g s, 20 s\n%-16s %-15s %12s %12s %10s\n", h, "method", "spin axis", "energy", "|dL|/|L|", "max tilt");
    for (int method = 0; method < 4; method++)
        for (int axis = 0; axis < 3; axis++) {
            quat q = q_identity();
            vec3 w = v3(axis == 0 ? 10 : 0.01, axis == 1 ? 10 : 0.01, axis == 2 ? 10 : 0.01);
            vec3 L0 = v3_mul(inertia, w);
            double e0 = 0.5 * v3_dot(w, L0), tilt = 0;
            int n = (int)(20.0 / h + 0.5);
            for (int i = 0; i < n; i++) {
                rotation_step_method((rotation_method)method, &q, &w, inertia, h);
                vec3 e = q_rotate(q, v3(axis == 0, axis == 1, axis == 2));
                double c = fabs(v3_get(e, axis));
                double a = acos(c > 1 ? 1 : c) * 57.29577951308232;
                if (a > tilt) tilt = a;
            }
            mat3 I = m3_rotate_tensor(m3_from_quat(q), m3_diag(inertia));
            vec3 L = m3_mulv(I, w);
            double e = 0.5 * v3_dot(w, L);
            printf("%-16s %-15s %+11.3e %12.3e %9.2f\n", names[method], axes[axis], e / e0 - 1,
                   v3_len(v3_sub(L, L0)) / v3_len(L0), tilt);
        }
    return 0;
}
