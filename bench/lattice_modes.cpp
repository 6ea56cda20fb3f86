// The lattice's lowest vibration modes on the sparse path (ga_modes_near), against a dynamic
// step of the same model, and at about 10^4 unknowns against LAPACK on the dense matrices.
//
//   lattice_modes NY [verify]
//
// The lattice (examples/scenes/lattice.h) has 4 NY x NY nodes, n = 2 (4 NY - 1) NY unknowns,
// springs k = 1e6 (NY / 8)^2 (a larger structure of a stiffer material, so that it sags by
// about the same 0.16 m) and 10 times that in its outer half. It is found at rest under
// gravity (ga_static_equilibrium, the sparse saddle-point Newton), then its 10 lowest modes
// (sigma = 0). Timed in interleaved rounds: the modes' set-up (pattern, ordering) and
// factorization of [K_t - sigma M] alone, ga_modes_near whole, and a dynamic run's ga_init
// and steps from the unstressed lattice (rho_inf 0.9, h = 1e-3, constant mass, exact K_t) --
// its first step (which factorizes the iteration matrix) and the mean of 9 more. Memory:
// the peak resident set after each phase (this process, in its order). "verify": LAPACK's
// dsyevr on the dense K_t / mass for the 10 lowest eigenvalues, and the largest relative
// difference (dense, n^2 doubles: for n up to about 2 10^4).
//
// CSV on stdout: unknowns,phase,seconds_median,seconds_q1,seconds_q3,peak_rss_kib,value
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "../src/capi_internal.hpp"
#include "../src/saddle_at_rest.hpp"

#include "scenes/lattice.h"

extern "C" void dsyevr_(const char *jobz, const char *range, const char *uplo, const int *n,
                        double *a, const int *lda, const double *vl, const double *vu,
                        const int *il, const int *iu, const double *abstol, int *m, double *w,
                        double *z, const int *ldz, int *isuppz, double *work, const int *lwork,
                        int *iwork, const int *liwork, int *info);

namespace {

using clock_type = std::chrono::steady_clock;
double since(clock_type::time_point t0)
{
    return std::chrono::duration<double>(clock_type::now() - t0).count();
}

long peak_kib()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss;
}

[[noreturn]] void fail(ga_solver *s, const char *what)
{
    std::fprintf(stderr, "%s: %s\n", what, s ? ga_last_error(s) : "");
    std::exit(1);
}

ga_solver *make(lattice &l)
{
    ga_solver *s = nullptr;
    if (ga_create(l.n, 0, &s) || lattice_declare_patterns(&l, s) ||
        ga_set_callbacks(s, lattice_mass, lattice_force, nullptr, nullptr, &l) ||
        ga_set_tangents(s, lattice_stiffness, nullptr) || ga_set_constant_mass(s, 1) ||
        ga_set_rho_inf(s, 0.9) || ga_set_linear_solver(s, GA_LINEAR_SPARSE))
        fail(s, "set-up");
    return s;
}

struct Quartiles {
    double q1, median, q3;
};
Quartiles quartiles(std::vector<double> x)
{
    std::sort(x.begin(), x.end());
    const auto at = [&](double p) { return x[static_cast<std::size_t>(p * (x.size() - 1) + 0.5)]; };
    return {at(0.25), at(0.5), at(0.75)};
}

void row(int n, const char *phase, const std::vector<double> &t, long kib, double value)
{
    const Quartiles q = t.empty() ? Quartiles{0, 0, 0} : quartiles(t);
    std::printf("%d,%s,%.6e,%.6e,%.6e,%ld,%.17g\n", n, phase, q.median, q.q1, q.q3, kib, value);
}

}  // namespace

int main(int argc, char **argv)
{
    const int ny = argc > 1 ? std::atoi(argv[1]) : 36;
    const bool verify = argc > 2 && std::strcmp(argv[2], "verify") == 0;
    const int rounds = 5, count = 10;
    lattice l;
    const double k = 1e6 * (ny / 8.0) * (ny / 8.0);
    if (ny < 2 || lattice_make(&l, 4 * ny, ny, k, 10.0))
        fail(nullptr, "lattice");
    const int n = l.n;
    std::printf("unknowns,phase,seconds_median,seconds_q1,seconds_q3,peak_rss_kib,value\n");
    const long base = peak_kib();
    row(n, "baseline", {}, base, 0.0);

    // rest under gravity
    ga_solver *s = make(l);
    std::vector<double> q(n, 0.0);
    auto t0 = clock_type::now();
    if (ga_static_equilibrium(s, 0.0, q.data(), nullptr, 1e-12, 50))
        fail(s, "ga_static_equilibrium");
    row(n, "static_equilibrium", {since(t0)}, peak_kib(), q[n - 1]);

    std::vector<double> w2(count), setup_fact, modes, init, first, mean_step;
    std::vector<double> shapes(static_cast<std::size_t>(n) * count);
    std::vector<double> zero(n, 0.0), qd(n);
    long kib_setup = 0, kib_modes = 0, kib_dyn = 0;
    for (int r = 0; r < rounds; ++r) {
        {  // the modes' set-up and factorization alone (what ga_modes_near does first)
            ga::Stepper &kernel = s->core.kernel();
            const ga::Vec qv = Eigen::Map<const ga::Vec>(q.data(), n);
            t0 = clock_type::now();
            ga::SaddleAtRest at(kernel, 0.0);
            if (at.mass(qv) || at.stiffness(qv, ga::Vec(0)) || !at.factorize(0.0, 1.0))
                fail(s, "factorization");
            setup_fact.push_back(since(t0));
            kib_setup = std::max(kib_setup, peak_kib());
        }
        t0 = clock_type::now();
        if (ga_modes_near(s, 0.0, q.data(), nullptr, 0.0, count, w2.data(), shapes.data()))
            fail(s, "ga_modes_near");
        modes.push_back(since(t0));
        kib_modes = std::max(kib_modes, peak_kib());
        // a dynamic run of the same lattice from its unstressed start
        ga_solver *d = make(l);
        ga_set_newton(d, 1e-6, 20);
        std::fill(qd.begin(), qd.end(), 0.0);
        t0 = clock_type::now();
        if (ga_init(d, 0.0, qd.data(), zero.data()))
            fail(d, "ga_init");
        init.push_back(since(t0));
        t0 = clock_type::now();
        if (ga_step(d, 1e-3))
            fail(d, "ga_step");
        first.push_back(since(t0));
        t0 = clock_type::now();
        for (int i = 0; i < 9; ++i)
            if (ga_step(d, 1e-3))
                fail(d, "ga_step");
        mean_step.push_back(since(t0) / 9.0);
        kib_dyn = std::max(kib_dyn, peak_kib());
        ga_free(d);
    }
    row(n, "modes_setup_and_factorization", setup_fact, kib_setup, 0.0);
    row(n, "modes_near_10", modes, kib_modes, w2[0]);
    row(n, "dynamic_init", init, kib_dyn, 0.0);
    row(n, "dynamic_first_step", first, kib_dyn, 0.0);
    row(n, "dynamic_mean_step", mean_step, kib_dyn, 0.0);
    std::vector<double> ratio_first(rounds), ratio_mean(rounds);
    for (int r = 0; r < rounds; ++r) {
        ratio_first[r] = setup_fact[r] / first[r];
        ratio_mean[r] = setup_fact[r] / mean_step[r];
    }
    row(n, "ratio_setup_factorization_to_first_step", {}, 0, quartiles(ratio_first).median);
    row(n, "ratio_setup_factorization_to_mean_step", {}, 0, quartiles(ratio_mean).median);
    for (int i = 0; i < count; ++i)
        row(n, "omega2", {}, 0, w2[i]);

    if (verify) {  // LAPACK on the dense matrices: K_t / mass, M = mass I
        std::vector<double> vals(l.nnz);
        lattice_stiffness_values(&l, q.data(), vals.data());
        std::vector<double> A(static_cast<std::size_t>(n) * n, 0.0);
        for (int i = 0; i < n; ++i)
            for (int p = l.rowptr[i]; p < l.rowptr[i + 1]; ++p)
                A[i + static_cast<std::size_t>(n) * l.colind[p]] += vals[p] / l.mass;
        const int il = 1, iu = count;
        const double none = 0.0, abstol = 0.0;
        int found = 0, info = 0, lwork = -1, liwork = -1, iw = 0;
        double wq = 0.0;
        std::vector<double> ev(n), z(1);
        std::vector<int> isuppz(2 * count);
        t0 = clock_type::now();
        dsyevr_("N", "I", "U", &n, A.data(), &n, &none, &none, &il, &iu, &abstol, &found, ev.data(),
                z.data(), &n, isuppz.data(), &wq, &lwork, &iw, &liwork, &info);
        lwork = static_cast<int>(wq);
        liwork = iw;
        std::vector<double> work(lwork);
        std::vector<int> iwork(liwork);
        dsyevr_("N", "I", "U", &n, A.data(), &n, &none, &none, &il, &iu, &abstol, &found, ev.data(),
                z.data(), &n, isuppz.data(), work.data(), &lwork, iwork.data(), &liwork, &info);
        if (info != 0 || found != count)
            fail(nullptr, "dsyevr");
        const double lapack = since(t0);
        double worst = 0.0;
        for (int i = 0; i < count; ++i)
            worst = std::max(worst, std::fabs(w2[i] - ev[i]) / ev[i]);
        row(n, "lapack_dsyevr_10", {lapack}, peak_kib(), ev[0]);
        row(n, "max_relative_difference_to_lapack", {}, 0, worst);
    }
    ga_free(s);
    lattice_free(&l);
    return 0;
}
