/* The paper's slider-crank (sec. 5.1): rho_inf = 0.7, h = 5e-3, t in [0, 1]. */
#include <math.h>
#include <stdio.h>

#include "demo_run.h"
#include "scenes/slider_crank.h"

int main(void)
{
    slider_crank p = slider_crank_paper();
    double q0[SC_N], v0[SC_N];
    sc_initial(&p, M_PI / 2, q0, v0);
    static const char *names[] = {"theta1", "theta2", "x3", "x4"};
    static const int show[] = {SC_TH1, SC_TH2, SC_X3, SC_X4, -1};
    const demo_scene d = {"Slider-crank with spring and mass (Arnold & Bruls 2007, sec. 5.1)",
                          SC_N, SC_M, sc_mass, sc_force, sc_constraint, sc_jacobian,
                          sc_stiffness, sc_constraint_accel, &p, q0, v0, 0.7, 5e-3, 1.0, names,
                          show, 1};
    return demo_run(&d, NULL, NULL);
}
