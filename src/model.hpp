// ga::Model: the user's callbacks behind one interface. Maps callback return codes to statuses,
// rejects non-finite outputs, counts evaluations, and supplies finite-difference fallbacks for
// the optional pieces (tangent stiffness, tangent damping, constraint acceleration term, Phi_t).
#pragma once

#include "diagnostics.hpp"
#include "types.hpp"

namespace ga {

struct Callbacks {
    ga_mass_fn mass = nullptr;
    ga_force_fn force = nullptr;
    ga_constraint_fn constraint = nullptr;
    ga_jacobian_fn jacobian = nullptr;
    ga_stiffness_fn stiffness = nullptr;
    ga_damping_fn damping = nullptr;
    ga_constraint_accel_fn constraint_accel = nullptr;
    void *user = nullptr;
};

class Model {
public:
    Model(int n, int m, Counters &counters, Diagnostics &diag);

    // Scratch for finite differences; sized once at setup, never in a step.
    void allocate_workspace();

    Callbacks cb;
    ga_tangent_mode tangent_mode = GA_TANGENT_AUTO;

    bool ready() const { return cb.mass != nullptr && (m_ == 0 || (cb.constraint && cb.jacobian)); }
    bool uses_tangents() const { return tangent_mode != GA_TANGENT_NEGLECT; }

    ga_status mass(double t, const Vec &q, Mat &M);
    ga_status force(double t, const Vec &q, const Vec &v, Vec &f);
    ga_status constraint(double t, const Vec &q, Vec &phi);
    ga_status jacobian(double t, const Vec &q, Mat &Phi_q);

    // K_t = d r^q / dq at fixed v, qdd, lambda. rq is r^q at q (used by finite differences).
    ga_status stiffness(double t, const Vec &q, const Vec &v, const Vec &qdd, const Vec &lambda,
                        const Vec &rq, Mat &K);
    // C_t = -df/dv. f is f(q, v, t) (used by finite differences).
    ga_status damping(double t, const Vec &q, const Vec &v, const Vec &f, Mat &C);
    // Phi_qq(v, v) + 2 Phi_qt v + Phi_tt.
    ga_status constraint_accel(double t, const Vec &q, const Vec &v, Vec &out);
    // Phi_t by central differences in t (exactly zero for time-independent constraints).
    ga_status constraint_dt(double t, const Vec &q, Vec &out);

    // r^q = M qdd - f + Phi_q^T lambda: the residual of eq. (1), not weighted.
    static void dynamics_residual(const Mat &M, const Vec &qdd, const Vec &f, const Mat &Phi_q,
                                  const Vec &lambda, Vec &rq);

private:
    ga_status callback_status(int rc, const char *name, double t);
    ga_status check_finite(const double *x, Eigen::Index rows, Eigen::Index cols,
                           const char *what, double t);

    int n_, m_;
    Counters &counters_;
    Diagnostics &diag_;
    // finite-difference scratch
    Vec q_pert_, v_pert_, f_pert_, r_pert_, phi_plus_, phi_minus_, g_plus_, g_minus_;
    Mat M_pert_, J_pert_;
};

}  // namespace ga
