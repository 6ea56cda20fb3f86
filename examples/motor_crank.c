/* The slider-crank driven by a DC motor under a PI speed controller (scenes/
 * slider_crank_motor.h): the motor current and the controller's integral are first-order
 * states, integrated in the same Newton solve as the mechanism (ga_set_first_order).
 * rho_inf = 0.8, h = 1e-3, t in [0, 2]. Prints the final state, how well the speed follows
 * its reference, the work; with a file name, also writes t, speed, reference, current and
 * integral every 5 ms (CSV) for a chart. */
#include <math.h>
#include <stdio.h>
#include <time.h>

#include <galpha.h>

#include "scenes/slider_crank_motor.h"

static int fail(ga_solver *s, const char *what)
{
    fprintf(stderr, "%s: %s\n", what, ga_last_error(s));
    ga_free(s);
    return 1;
}

int main(int argc, char **argv)
{
    sc_motor p = sc_motor_default();
    double q[SC_N], v[SC_N], lambda[SC_M], y[SCM_R] = {0.0, 0.0}, ydot[SCM_R];
    sc_initial(&p.crank, M_PI / 2, q, v);
    ga_solver *s = NULL;
    if (ga_create(SC_N, SC_M, &s) != GA_OK)
        return 1;
    if (ga_set_callbacks(s, sc_mass, NULL, sc_constraint, sc_jacobian, &p) ||
        ga_set_constraint_accel(s, sc_constraint_accel) ||
        ga_set_tangents(s, sc_stiffness, NULL) ||
        ga_set_first_order(s, SCM_R, scm_force, scm_rate) || ga_set_coupling(s, scm_coupling) ||
        ga_set_rho_inf(s, 0.8))
        return fail(s, "setup");
    FILE *csv = argc > 1 ? fopen(argv[1], "w") : NULL;
    if (argc > 1 && !csv) {
        perror(argv[1]);
        ga_free(s);
        return 1;
    }
    if (csv)
        fprintf(csv, "t,speed,reference,current,integral\n");
    const double h = 1e-3, t_end = 2.0;
    const int steps = (int)lround(t_end / h);
    const clock_t start = clock();
    if (ga_init_y(s, 0.0, q, v, y) != GA_OK)
        return fail(s, "ga_init_y");
    double sum_sq = 0.0, peak_current = 0.0;
    int counted = 0;
    for (int k = 1; k <= steps; ++k) {
        if (ga_step(s, h) != GA_OK)
            return fail(s, "ga_step");
        double t;
        ga_get_t(s, &t);
        ga_get_v(s, v);
        ga_get_y(s, y, NULL);
        const double error = v[SC_TH1] - scm_reference_speed(&p, t);
        if (t > 1.0) { /* the second second: after the ramp */
            sum_sq += error * error;
            ++counted;
        }
        peak_current = fmax(peak_current, fabs(y[SCM_I]));
        if (csv && k % 5 == 0)
            fprintf(csv, "%.4f,%.6f,%.6f,%.6f,%.6f\n", t, v[SC_TH1],
                    scm_reference_speed(&p, t), y[SCM_I], y[SCM_Z]);
    }
    const double seconds = (double)(clock() - start) / CLOCKS_PER_SEC;
    if (csv)
        fclose(csv);
    ga_get_q(s, q);
    ga_get_lambda(s, lambda);
    ga_get_y(s, y, ydot);
    long long newton = 0, factorizations = 0;
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &newton);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &factorizations);
    printf("Slider-crank driven by a DC motor with a PI speed controller (C), rho_inf = 0.8, "
           "h = 1e-3, t = 2\n");
    printf("final q =");
    for (int i = 0; i < SC_N; ++i)
        printf(" %.17e", q[i]);
    printf("\nfinal lambda =");
    for (int i = 0; i < SC_M; ++i)
        printf(" %.17e", lambda[i]);
    printf("\nfinal y =");
    for (int i = 0; i < SCM_R; ++i)
        printf(" %.17e", y[i]);
    printf("\ncrank speed %.3f rad/s (reference %.3f); RMS speed error over [1, 2] s %.3f rad/s; "
           "peak current %.1f A\n",
           v[SC_TH1], scm_reference_speed(&p, t_end), sqrt(sum_sq / counted), peak_current);
    printf("steps = %d, Newton iterations = %lld, factorizations = %lld, %.1f ms\n", steps, newton,
           factorizations, 1e3 * seconds);
    ga_free(s);
    return 0;
}
