/* Andrews' squeezing mechanism (paper sec. 5.2), rho_inf = 0.7, h = 3e-4, t in [0, 0.03], in
 * the Test Set's 7 relative angles and in the paper's 31 absolute coordinates, side by side,
 * with the error against the published reference solution. */
#include <math.h>
#include <stdio.h>

#include "demo_run.h"
#include "scenes/andrews.h"


int main(void)
{
    const double h = 3e-4;
    double v7[AN7_N] = {0}, q31[AN31_N], v31[AN31_N], q[AN31_N], lam[AN31_M], ang[7];
    static const char *names7[] = {"beta", "Theta", "gamma"};
    static const int show7[] = {0, 1, 2, -1};
    const demo_scene a7 = {"Andrews' mechanism, 7 relative angles (Test Set formulation)",
                           AN7_N, AN7_M, an7_mass, an7_force, an7_constraint, an7_jacobian,
                           NULL, an7_constraint_accel, NULL, andrews_q0, v7, 0.7, h,
                           andrews_t_end, names7, show7, 0};
    if (demo_run(&a7, q, lam))
        return 1;
    printf("  relative 2-norm error of the 7 angles vs the published reference: %.3e; "
           "lambda_1 vs reference: %.3e\n",
           andrews_angle_error(q), fabs(lam[0] - andrews_lambda_ref[0]) / andrews_lambda_ref[0]);

    an31_from_angles(andrews_q0, v7, q31, v31);
    static const char *names31[] = {"th1 = beta", "x_F", "y_F"};
    const int show31[] = {an31_theta(1), an31_point('F'), an31_point('F') + 1, -1};
    const demo_scene a31 = {"Andrews' mechanism, 31 absolute coordinates (paper sec. 5.2)",
                            AN31_N, AN31_M, an31_mass, an31_force, an31_constraint,
                            an31_jacobian, an31_stiffness, an31_constraint_accel, NULL, q31, v31,
                            0.7, h, andrews_t_end, names31, show31, 0};
    if (demo_run(&a31, q, lam))
        return 1;
    an31_to_angles(q, ang);
    printf("  relative 2-norm error of the 7 angles vs the published reference: %.3e; "
           "force at E on the triangle vs reference lambda_1: %.3e\n",
           andrews_angle_error(ang), fabs(lam[24] - andrews_lambda_ref[0]) / andrews_lambda_ref[0]);
    return 0;
}
