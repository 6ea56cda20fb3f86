/* Embedding galpha in a host simulator that owns the time loop.
 *
 * The host below is written as a legacy code would be: its model is a gantry crane (a
 * trolley on a rail carrying a load on a rigid cable) in plain arrays and plain functions,
 * with no galpha type anywhere; a fixed time loop, a controller that reads the state back
 * after every step and changes the drive force on the trolley for the next one, and a log.
 * galpha sees the model only through four small adapters that forward to the host's code.
 *
 * Coordinates: q = (x_trolley, x_load, y_load); one constraint, the cable length:
 * (x_load - x_trolley)^2 + y_load^2 - L^2 = 0. */
#include <galpha.h>
#include <math.h>
#ifndef M_PI /* not in strict C99 */
#define M_PI 3.14159265358979323846
#endif
#include <stdio.h>

/* ======================= the host's own code (no galpha inside) ========================= */
struct crane {
    double m_trolley, m_load, cable, g;
    double drive; /* force on the trolley, set by the host's controller between steps */
};

static void crane_mass(const struct crane *c, double M[9])
{
    for (int i = 0; i < 9; ++i)
        M[i] = 0.0;
    M[0] = c->m_trolley;
    M[4] = c->m_load;
    M[8] = c->m_load;
}

static void crane_forces(const struct crane *c, const double q[3], const double v[3], double f[3])
{
    (void)q;
    f[0] = c->drive - 2.0 * v[0]; /* drive and rail friction */
    f[1] = 0.0;
    f[2] = -c->m_load * c->g;
}

static void crane_cable(const struct crane *c, const double q[3], double *phi, double J[3])
{
    const double dx = q[1] - q[0];
    *phi = dx * dx + q[2] * q[2] - c->cable * c->cable;
    J[0] = -2.0 * dx;
    J[1] = 2.0 * dx;
    J[2] = 2.0 * q[2];
}

/* Tracking control of a smooth move (a quintic from 0 to target in 6 s, slow against the
 * load's 2.8 s swing period, so the load arrives calm). */
static double crane_controller(double t, double target, const double q[3], const double v[3])
{
    const double T = 6.0, tau = t < T ? t / T : 1.0;
    const double x_ref = target * tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    const double v_ref = t < T ? target * 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / T : 0.0;
    return 3000.0 * (x_ref - q[0]) + 800.0 * (v_ref - v[0]);
}

/* ======================= adapters: galpha callbacks -> host code ======================== */
static int ad_mass(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q;
    crane_mass(user, M);
    return 0;
}
static int ad_force(double t, const double *q, const double *v, double *f, void *user)
{
    (void)t;
    crane_forces(user, q, v, f);
    return 0;
}
static int ad_constraint(double t, const double *q, double *phi, void *user)
{
    double J[3];
    (void)t;
    crane_cable(user, q, phi, J);
    return 0;
}
static int ad_jacobian(double t, const double *q, double *J, void *user)
{
    double phi;
    (void)t;
    crane_cable(user, q, &phi, J); /* 1 x 3: the gradient */
    return 0;
}

/* ======================= the host's main loop ============================================ */
int main(void)
{
    struct crane crane = {10.0, 50.0, 2.0, 9.81, 0.0};
    double q[3] = {0.0, 0.0, -2.0}, v[3] = {0.0, 0.0, 0.0}; /* load hanging at rest */
    const double dt = 0.01, target = 3.0;
    double max_phi = 0.0;
    ga_solver *s = NULL;

    if (ga_create(3, 1, &s) || ga_set_callbacks(s, ad_mass, ad_force, ad_constraint,
                                                ad_jacobian, &crane) ||
        ga_set_rho_inf(s, 0.8) || ga_init(s, 0.0, q, v)) {
        fprintf(stderr, "setup failed: %s\n", ga_last_error(s));
        return 1;
    }
    printf("   t [s]   trolley x [m]   swing [deg]   drive [N]\n");
    for (int k = 1; k <= 1000; ++k) {           /* the host's fixed loop: 10 s */
        crane.drive = crane_controller((k - 1) * dt, target, q, v); /* load for the step */
        const ga_status st = ga_step(s, dt);
        if (st != GA_OK) {                        /* state is still that of step k-1 */
            fprintf(stderr, "step %d: %s: %s\n", k, ga_strerror(st), ga_last_error(s));
            ga_free(s);
            return 1;
        }
        ga_get_q(s, q);                           /* read back into the host's arrays */
        ga_get_v(s, v);
        double phi, J[3];
        crane_cable(&crane, q, &phi, J);
        max_phi = fmax(max_phi, fabs(phi));
        if (k % 100 == 0)
            printf("%8.2f %15.6f %13.4f %11.3f\n", k * dt, q[0],
                   atan2(q[1] - q[0], -q[2]) * 180.0 / M_PI, crane.drive);
    }
    const double swing = atan2(q[1] - q[0], -q[2]) * 180.0 / M_PI;
    printf("after 10 s: trolley at %.4f m (target %.1f), swing %.4f deg, max |cable residual| "
           "%.1e\n",
           q[0], target, swing, max_phi);
    ga_free(s);
    /* the host's own acceptance: arrived, residual swing small, cable length kept */
    return fabs(q[0] - target) < 0.01 && fabs(swing) < 5.0 && max_phi < 1e-10 ? 0 : 1;
}
