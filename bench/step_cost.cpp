// Per-step cost against the unavoidable work: for each scene, the mean wall time of a fixed-step
// run (best of several) divided by the time of one residual evaluation plus one solve with a
// factorized iteration matrix (Solver::unavoidable_work, the same code the step runs).
// Also the N-link chain at one size given on the command line (scripts/bench.sh loops over N
// in separate processes, so that the peak memory of each size is its own).
//
//   step_cost scenes [tol]     -> CSV on stdout
//   step_cost chain N [steps]  -> one CSV line on stdout
//   step_cost scene_steps NAME [tol] | scene_limit NAME [tol] [reps]  -> for callgrind
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../src/capi_internal.hpp"
extern "C" {
#include "scenes/andrews.h"
#include "scenes/chain.h"
#include "scenes/pendulum.h"
#include "scenes/slider_crank.h"
#include "scenes/spatial_chain.h"
}

namespace {

using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0)
{
    return std::chrono::duration<double>(clock_type::now() - t0).count();
}

struct Scene {
    std::string name;
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_constraint_fn constraint;
    ga_jacobian_fn jacobian;
    ga_stiffness_fn stiffness;
    ga_constraint_accel_fn accel;
    void *user;
    std::vector<double> q0, v0;
    double h, t_end, rho;
    int constant_mass;
    ga_status (*declare)(ga_solver *, void *);  // declares patterns (sparse models)
    int formulation = GA_INDEX3;
    ga_constraint_fn dt = nullptr;  // Phi_t (index 2), central differences when null
    // a solver with its space, callbacks, tangents and patterns (in place of ga_create and the
    // callbacks above), when given
    ga_status (*create)(void *user, ga_solver **out) = nullptr;
};

ga_status create_spatial_chain(void *user, ga_solver **out)
{
    return spatial_chain_solver(static_cast<spatial_chain *>(user), out);
}

ga_status declare_chain(ga_solver *s, void *user) { return chain_declare_patterns(static_cast<chain *>(user), s); }
ga_status declare_andrews31(ga_solver *s, void *) { return an31_declare_patterns(s); }

struct Result {
    double per_step = 0, limit = 0, newton = 0, factorizations = 0;
    // the first step (which chooses pivots for the step's matrix, after ga_init's of another
    // matrix) and the mean of the others: what a long run pays per step
    double first_step = 0, later_per_step = 0;
    // ga_create, the options and patterns, and ga_init: what a run pays before its first step
    double setup = 0;
    long long steps = 0;
    std::string backend;
};

ga_solver *make(const Scene &sc, int solver, double tol)
{
    ga_solver *s = nullptr;
    if (sc.create) {
        if (sc.create(sc.user, &s))
            return nullptr;
    } else {
        if (ga_create(sc.n, sc.m, &s))
            return nullptr;
        if (sc.declare)
            sc.declare(s, sc.user);
        ga_set_callbacks(s, sc.mass, sc.force, sc.constraint, sc.jacobian, sc.user);
        ga_set_tangents(s, sc.stiffness, nullptr);
        ga_set_constraint_accel(s, sc.accel);
        ga_set_constraint_dt(s, sc.dt);
    }
    ga_set_rho_inf(s, sc.rho);
    ga_set_newton(s, tol, 20);
    ga_set_constant_mass(s, sc.constant_mass);
    ga_set_linear_solver(s, solver);
    ga_set_formulation(s, sc.formulation);
    if (const char *mode = std::getenv("GA_TANGENT_MODE"))
        ga_set_tangent_mode(s, std::atoi(mode));
    if (const char *pred = std::getenv("GA_PREDICTOR"))
        ga_set_predictor(s, std::atoi(pred));
    return s;
}

Result measure(const Scene &sc, int solver, double tol, int repeats)
{
    Result r;
    const long steps = std::lround(sc.t_end / sc.h);
    for (int rep = 0; rep < repeats; ++rep) {
        const auto t_setup = clock_type::now();
        ga_solver *s = make(sc, solver, tol);
        if (ga_init(s, 0.0, sc.q0.data(), sc.v0.data())) {
            std::fprintf(stderr, "%s: %s\n", sc.name.c_str(), ga_last_error(s));
            std::exit(1);
        }
        const double setup = seconds_since(t_setup);
        if (rep == 0 || setup < r.setup)
            r.setup = setup;
        const auto t0 = clock_type::now();
        double first = 0.0;
        for (long k = 0; k < steps; ++k) {
            if (ga_step(s, sc.h)) {
                std::fprintf(stderr, "%s: %s\n", sc.name.c_str(), ga_last_error(s));
                std::exit(1);
            }
            if (k == 0)
                first = seconds_since(t0);
        }
        const double total = seconds_since(t0);
        const double per_step = total / static_cast<double>(steps);
        // each the best over the runs, as the mean of all steps
        if (rep == 0 || first < r.first_step)
            r.first_step = first;
        if (steps > 1) {
            const double later = (total - first) / static_cast<double>(steps - 1);
            if (rep == 0 || later < r.later_per_step)
                r.later_per_step = later;
        }
        if (rep == 0 || per_step < r.per_step) {
            r.per_step = per_step;
            long long it, fa;
            ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &it);
            ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &fa);
            r.newton = static_cast<double>(it) / static_cast<double>(steps);
            r.factorizations = static_cast<double>(fa - 1) / static_cast<double>(steps);
            r.steps = steps;
            r.backend = ga_linear_solver_name(s);
        }
        if (rep == 0 && sc.formulation != GA_INDEX3) {
            r.limit = std::nan("");  // Solver::unavoidable_work is the index-3 step's
        } else if (rep == 0) {
            // the unavoidable work at the final state, with the factorization at hand
            ga::Stepper &core = s->core.kernel();
            core.unavoidable_work(sc.h);  // makes a factorization if there is none
            // about a second of repetitions whatever the size
            const int reps = std::max(3, static_cast<int>(2e5 / (sc.n + sc.m)));
            double best = 1e300;
            for (int block = 0; block < 5; ++block) {
                const auto t1 = clock_type::now();
                for (int k = 0; k < reps; ++k)
                    core.unavoidable_work(sc.h);
                best = std::min(best, seconds_since(t1) / reps);
            }
            r.limit = best;
        }
        ga_free(s);
    }
    return r;
}

// The chain at rest, h = 1e-3 for `steps` steps, declared patterns.
Scene chain_scene(chain &c, int steps)
{
    const int links = c.links;
    Scene sc{"chain", 3 * links, 2 * links, chain_mass, chain_force, chain_constraint,
             chain_jacobian, chain_stiffness, chain_constraint_accel, &c,
             std::vector<double>(3 * links), std::vector<double>(3 * links), 1e-3,
             steps * 1e-3, 0.7, 1, declare_chain};
    chain_initial(&c, sc.q0.data(), sc.v0.data());
    return sc;
}

slider_crank g_sc;

std::vector<Scene> paper_scenes()
{
    std::vector<Scene> out;
    g_sc = slider_crank_paper();
    Scene sc{"slider_crank", SC_N, SC_M, sc_mass, sc_force, sc_constraint, sc_jacobian,
             sc_stiffness, sc_constraint_accel, &g_sc, std::vector<double>(SC_N),
             std::vector<double>(SC_N), 5e-3, 1.0, 0.7, 1, nullptr};
    (void)declare_chain;
    sc_initial(&g_sc, M_PI / 2, sc.q0.data(), sc.v0.data());
    out.push_back(sc);
    Scene a7{"andrews7", AN7_N, AN7_M, an7_mass, an7_force, an7_constraint, an7_jacobian,
             nullptr, an7_constraint_accel, nullptr,
             std::vector<double>(andrews_q0, andrews_q0 + 7), std::vector<double>(7), 3e-4,
             andrews_t_end, 0.7, 0, nullptr};
    out.push_back(a7);
    Scene a31{"andrews31", AN31_N, AN31_M, an31_mass, an31_force, an31_constraint,
              an31_jacobian, an31_stiffness, an31_constraint_accel, nullptr,
              std::vector<double>(AN31_N), std::vector<double>(AN31_N), 3e-4, andrews_t_end,
              0.7, 1, nullptr};
    double v7[7] = {0};
    an31_from_angles(andrews_q0, v7, a31.q0.data(), a31.v0.data());
    out.push_back(a31);
    Scene a31s = a31;
    a31s.name = "andrews31_sparse";
    a31s.mass = an31_mass_sparse;
    a31s.jacobian = an31_jacobian_sparse;
    a31s.stiffness = an31_stiffness_sparse;
    a31s.declare = declare_andrews31;
    out.push_back(a31s);
    return out;
}

long peak_rss_kib()
{
    FILE *f = std::fopen("/proc/self/status", "r");
    char line[256];
    long kib = -1;
    while (f && std::fgets(line, sizeof line, f))
        if (std::strncmp(line, "VmHWM:", 6) == 0)
            kib = std::atol(line + 6);
    if (f)
        std::fclose(f);
    return kib;
}

}  // namespace

int main(int argc, char **argv)
{
    const std::string mode = argc > 1 ? argv[1] : "scenes";
    if (mode == "scenes") {
        const double tol = argc > 2 ? std::atof(argv[2]) : 1e-10;
        std::printf("scene,backend,newton_tol,n,m,steps,newton_per_step,factorizations_per_step,"
                    "us_per_step,limit_us,ratio\n");
        for (const Scene &sc : paper_scenes()) {
            const bool sparse = sc.declare != nullptr;
            for (int solver : {GA_LINEAR_DENSE, GA_LINEAR_DENSE_EIGEN, GA_LINEAR_DENSE_LAPACK,
                               GA_LINEAR_SPARSE}) {
                if (sparse != (solver == GA_LINEAR_SPARSE))
                    continue;
                const Result r = measure(sc, solver, tol, 7);
                std::printf("%s,%s,%g,%d,%d,%lld,%.3f,%.3f,%.3f,%.3f,%.3f\n", sc.name.c_str(),
                            r.backend.c_str(), tol, sc.n, sc.m, r.steps, r.newton,
                            r.factorizations, 1e6 * r.per_step, 1e6 * r.limit,
                            r.per_step / r.limit);
                std::fflush(stdout);
            }
        }
        return 0;
    }
    if ((mode == "scene_steps" || mode == "scene_limit") && argc > 2) {
        // For instruction counts under callgrind: a scene's fixed-step run (collect inside
        // ga_step; prints the number of steps), or after it `reps` calls of the unavoidable
        // work (collect inside Solver::unavoidable_work; scripts/bench.sh takes the
        // difference of two counts of reps, so that nothing but those calls is counted).
        const std::string name = argv[2];
        const double tol = argc > 3 ? std::atof(argv[3]) : 1e-6;
        const int reps = argc > 4 ? std::atoi(argv[4]) : 1000;
        for (const Scene &sc : paper_scenes()) {
            if (sc.name != name)
                continue;
            ga_solver *s = make(sc, sc.declare ? GA_LINEAR_SPARSE : GA_LINEAR_DENSE, tol);
            if (ga_init(s, 0.0, sc.q0.data(), sc.v0.data()))
                return 1;
            const long steps = std::lround(sc.t_end / sc.h);
            for (long k = 0; k < steps; ++k)
                if (ga_step(s, sc.h))
                    return 1;
            if (mode == "scene_limit")
                for (int k = 0; k < reps; ++k)
                    s->core.kernel().unavoidable_work(sc.h);
            std::printf("%ld\n", steps);
            ga_free(s);
            return 0;
        }
        std::fprintf(stderr, "unknown scene %s\n", name.c_str());
        return 2;
    }
    if (mode == "chain_steps" && argc > 2) {
        // just the steps (for instruction counting under callgrind --toggle-collect=ga_step)
        const int links = std::atoi(argv[2]);
        const int steps = argc > 3 ? std::atoi(argv[3]) : 10;
        chain c = chain_make(links);
        Scene sc = chain_scene(c, steps);
        ga_solver *s = make(sc, GA_LINEAR_SPARSE, 1e-10);
        ga_init(s, 0.0, sc.q0.data(), sc.v0.data());
        for (int k = 0; k < steps; ++k)
            if (ga_step(s, sc.h))
                return 1;
        ga_free(s);
        return 0;
    }
    if ((mode == "chain" || mode == "chain_setup") && argc > 2) {
        const int links = std::atoi(argv[2]);
        const int steps = argc > 3 ? std::atoi(argv[3]) : 20;
        const double tol = argc > 4 ? std::atof(argv[4]) : 1e-10;
        const int formulation = argc > 5 ? std::atoi(argv[5]) : GA_INDEX3;
        chain c = chain_make(links);
        Scene sc = chain_scene(c, steps);
        sc.formulation = formulation;
        sc.dt = chain_constraint_dt;  // Phi_t = 0: no differences in t in index-2 steps
        // The best of several runs, as for the scenes; small chains take a few milliseconds
        // per run, where one descheduling shows, so they get more runs (about a second).
        const int repeats = std::max(3, std::min(200, static_cast<int>(1e6 / (sc.n + sc.m))));
        const Result r = measure(sc, GA_LINEAR_SPARSE, tol, repeats);
        if (mode == "chain_setup") {  // what a run pays before its first step, in steps
            std::printf("%d,%d,%d,%d,%.3f,%.3f,%.3f\n", links, sc.n, sc.m, repeats, 1e6 * r.setup,
                        1e6 * r.later_per_step, r.setup / r.later_per_step);
            return 0;
        }
        std::printf("%d,%d,%d,%s,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%ld\n", links, sc.n, sc.m,
                    r.backend.c_str(), steps, r.newton, r.factorizations, 1e6 * r.per_step,
                    1e6 * r.first_step, 1e6 * r.later_per_step, 1e6 * r.limit,
                    r.per_step / r.limit, peak_rss_kib());
        return 0;
    }
    if (mode == "spatial_chain_steps" && argc > 2) {  // for callgrind, as chain_steps
        const int bodies = std::atoi(argv[2]);
        const int steps = argc > 3 ? std::atoi(argv[3]) : 10;
        spatial_chain c = spatial_chain_make(bodies, 2.0);
        std::vector<double> q(7 * static_cast<std::size_t>(bodies)),
            v(6 * static_cast<std::size_t>(bodies));
        spatial_chain_initial(&c, q.data(), v.data());
        ga_solver *s = nullptr;
        if (spatial_chain_solver(&c, &s) || ga_set_rho_inf(s, 0.7) || ga_set_newton(s, 1e-10, 20) ||
            ga_set_linear_solver(s, GA_LINEAR_SPARSE) || ga_init(s, 0.0, q.data(), v.data()))
            return 1;
        for (int k = 0; k < steps; ++k)
            if (ga_step(s, 1e-3))
                return 1;
        ga_free(s);
        return 0;
    }
    if (mode == "spatial_chain" && argc > 2) {
        // N rods on R^3 x SO(3) joined by spherical joints (sparse path on a group space),
        // spinning about their axes as they fall; the chain's columns
        const int bodies = std::atoi(argv[2]);
        const int steps = argc > 3 ? std::atoi(argv[3]) : 20;
        spatial_chain c = spatial_chain_make(bodies, 2.0);
        Scene sc{"spatial_chain", 6 * bodies, 3 * bodies, nullptr, nullptr, nullptr, nullptr,
                 nullptr, nullptr, &c, {}, {}, 1e-3, steps * 1e-3, 0.7, 1, nullptr};
        sc.create = create_spatial_chain;
        sc.q0.resize(7 * static_cast<std::size_t>(bodies));
        sc.v0.resize(6 * static_cast<std::size_t>(bodies));
        spatial_chain_initial(&c, sc.q0.data(), sc.v0.data());
        const int repeats = std::max(3, std::min(200, static_cast<int>(1e6 / (sc.n + sc.m))));
        const Result r = measure(sc, GA_LINEAR_SPARSE, 1e-10, repeats);
        std::printf("%d,%d,%d,%s,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%ld\n", bodies, sc.n, sc.m,
                    r.backend.c_str(), steps, r.newton, r.factorizations, 1e6 * r.per_step,
                    1e6 * r.first_step, 1e6 * r.later_per_step, 1e6 * r.limit,
                    r.per_step / r.limit, peak_rss_kib());
        return 0;
    }
    std::fprintf(stderr, "usage: step_cost scenes [tol] | step_cost chain N [steps] [tol] "
                         "[formulation] | step_cost spatial_chain N [steps] | step_cost "
                         "scene_steps|scene_limit NAME [tol] [reps]\n");
    return 2;
}
