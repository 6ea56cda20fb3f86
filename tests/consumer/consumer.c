/* A program that knows galpha only through its installed header and pkg-config. */
#include <galpha.h>
#include <math.h>
#include <stdio.h>

static int mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = 1.0;
    return 0;
}

static int force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -q[0]; /* q'' = -q: q(t) = cos t */
    return 0;
}

int main(void)
{
    ga_solver *s = NULL;
    double q = 1.0, v = 0.0;
    if (ga_create(1, 0, &s) || ga_set_callbacks(s, mass, force, NULL, NULL, NULL) ||
        ga_init(s, 0.0, &q, &v))
        return 1;
    for (int i = 0; i < 1000; ++i)
        if (ga_step(s, 1e-3) != GA_OK)
            return 1;
    ga_get_q(s, &q);
    ga_free(s);
    printf("galpha %s (header %d.%d.%d): q(1) = %.9f, cos(1) = %.9f\n", ga_version(),
           GA_VERSION_MAJOR, GA_VERSION_MINOR, GA_VERSION_PATCH, q, cos(1.0));
    return fabs(q - cos(1.0)) < 1e-5 && ga_version_number() == GA_VERSION_NUMBER ? 0 : 1;
}
