// Forward sensitivities: the derivative of the discrete map of one step (docs/algorithms.md
// sec. 11). A converged step solves R(x_{n+1}, x_n, p) = 0; its derivative
//     R_{x_{n+1}} s_{n+1} = -R_{x_n} s_n - R_p
// is one more Newton iteration of Algorithm 1 on a linear problem: the predictor (eqs. 3-5
// with qdd_{n+1} = 0) applied to s_n, the residual linearized at the converged step, one solve
// with the exact iteration matrix there, and the update of eq. (7). Starts that are not this
// linear map (the consistent start, corrected starting values, Taylor steps) are
// differentiated by central differences of their own computation.
#include <array>
#include <cmath>
#include <limits>

#include "sensitivity.hpp"
#include "stepper.hpp"

namespace ga {

namespace {
const double kEps = std::numeric_limits<double>::epsilon();
}

void Sensitivities::allocate(int nq, int n, int m, int r)  // (n: nv)
{
    for (auto *set : {&accepted, &trial, &start}) {
        set->resize(np);
        for (StateDerivative &x : *set)
            x.allocate(n, m, r);
    }
    wide.allocate(n, m, r);
    for (Vec *x : {&ry, &dy, &gy, &w0, &rate_plus, &rate_minus})
        x->setZero(r);
    xq.setZero(nq);  // points: the rest are tangents
    q_pert.setZero(nq);
    for (Vec *x : {&rq, &d, &w, &f_plus, &f_minus, &bt, &a0, &xv, &cq, &cbt, &cq2, &cbt2,
                   &bracket})
        x->setZero(n);
    seed_q.assign(np, Vec::Zero(n));
    seed_v.assign(np, Vec::Zero(n));
    for (Vec *x : {&rl, &rv, &dl, &e, &cl, &cv, &phi, &cl2, &cv2})
        x->setZero(m);
}

void Sensitivities::allocate_matrices(const ModelMatrix &M, const ModelMatrix &J)
{
    M_pert.copy_layout(M);
    J_pert.copy_layout(J);
}

double Sensitivities::increment(int j) const { return std::cbrt(kEps) * scale[j]; }

double Sensitivities::extrapolated_increment(int j) const { return std::pow(kEps, 0.2) * scale[j]; }

namespace {
// half = (4 D(e/2) - D(e)) / 3 from half = D(e/2) and wide = D(e)
void extrapolate(Vec &half, const Vec &wide) { half = (4.0 / 3.0) * half - (1.0 / 3.0) * wide; }
}  // namespace

void ForwardSensitivity::set(int np, double *p, const double *p_scale, int depends, int nq, int nv,
                             int m, int r, const ModelMatrix *M, const ModelMatrix *J)
{
    Sensitivities s;  // built aside: a failed allocation leaves the old set
    s.np = np;
    s.p = np > 0 ? p : nullptr;
    s.depends = depends;
    s.scale.resize(np);
    for (int j = 0; j < np; ++j)
        s.scale[j] = p_scale ? p_scale[j] : (p[j] != 0.0 ? std::fabs(p[j]) : 1.0);
    if (np > 0) {
        s.allocate(nq, nv, m, r);  // (d/dp of q is a tangent: nv)
        if (M && J)
            s.allocate_matrices(*M, *J);
        scratch_.allocate(nq, nv, m);
        scratch_.allocate_first_order(r);
    }
    sens = std::move(s);
}

void ForwardSensitivity::set_start(int j, const double *dq0, const double *dv0, int nv)
{
    Vec q = dq0 ? Vec(Eigen::Map<const Vec>(dq0, nv)) : Vec::Zero(nv);
    Vec v = dv0 ? Vec(Eigen::Map<const Vec>(dv0, nv)) : Vec::Zero(nv);
    sens.seed_q[j].swap(q);  // (no allocation after the two above)
    sens.seed_v[j].swap(v);
}

// Runs `evaluate` with p_j at p_j + e and at p_j - e (and, through `perturb`, the state moved
// by the same multiple of its derivative); p_j is restored bit for bit whatever happens.
// Returns the divisor of the central difference in `span`.
template <class Perturb, class Evaluate>
ga_status ForwardSensitivity::central_difference(int j, Perturb &&perturb, Evaluate &&evaluate,
                                                 double &span, double increment)
{
    double &pj = sens.p[j];
    const double p0 = pj, e = increment > 0.0 ? increment : sens.increment(j);
    const double plus = p0 + e, minus = p0 - e;
    span = plus - minus;
    ga_status st = GA_OK;
    for (int side = 0; side < 2 && !st; ++side) {
        pj = side == 0 ? plus : minus;
        perturb(true, pj - p0);
        st = evaluate(side);
        perturb(false, 0.0);
        pj = p0;
    }
    pj = p0;
    return st;
}

// At ga_init: q0 and v0 depend on p as the seeds say (zero unless given), projected as the
// start projects q0 and v0 -- at a consistent point the derivative of the minimum-norm
// projections: dq0 onto Phi_q dq = 0, dv0 onto Phi_q dv = -d(Phi_q v + Phi_t)/dq dq0; qdd0 and
// lambda0 follow through the acceleration-level system they solve (central differences of
// that solve along (dq0, dv0) and p_j: it is linear in p, and cheap once).
ga_status ForwardSensitivity::start(const State &x)
{
    // Exact derivatives need every tangent in the matrix (step): on the sparse
    // path a tangent without a pattern has no place there.
    if (!k_.exact_tangents_fit())
        return k_.diag.fail(GA_ERR_ARG,
                            "sensitivities on the sparse path need the patterns of K_t "
                            "and C_t (ga_set_pattern; an empty pattern declares a zero matrix)");
    if (k_.sparse() && !k_.model.space.euclidean())
        return k_.diag.fail(GA_ERR_ARG, "sensitivities (forward and adjoint) on the sparse path "
                                        "are not available on a configuration space with "
                                        "rotations in this version (the dense solver has them)");
    if (k_.r() > 0 && !k_.coupling_exact)
        return k_.diag.fail(GA_ERR_ARG, "sensitivities with first-order states need the coupling "
                                        "blocks in the iteration matrix (ga_set_coupling_exact)");
    Sensitivities &z = sens;
    for (int j = 0; j < z.np; ++j) {
        StateDerivative &s = z.trial[j];
        s.q = z.seed_q[j];
        s.v = z.seed_v[j];
        const bool moves = (z.depends & GA_DEPENDS_CONSTRAINT) != 0;
        if (k_.m() > 0 && (moves || !s.q.isZero(0.0) || !s.v.isZero(0.0)))
            if (auto st = project_seeds(x, j, s)) {
                k_.diag.append(" (the start's derivative in parameter %d)", j);
                return st;
            }
        double span = 0.0;
        const auto perturb = [&](bool on, double shift) {
            if (!on)
                return;
            k_.model.space.shifted(x.q, shift, s.q, z.xq);
            z.xv = x.v + shift * s.v;
        };
        const auto evaluate = [&](int side) {
            Vec &qdd = side == 0 ? s.qdd : z.d;
            Vec &lambda = side == 0 ? s.lambda : z.dl;
            ga_status st = k_.start_accelerations(x.t, z.xq, z.xv, qdd, lambda);
            if (!st && k_.r() > 0)  // y'_0 = g(t0, q0, v0, y0), y0 independent of p
                st = k_.model.rate(x.t, z.xq, z.xv, x.y, side == 0 ? z.rate_plus : z.rate_minus);
            return st;
        };
        // extrapolated differences: in index 3 the start's error reaches dqdd/dp / (beta h^2)
        const auto pass = [&](double increment) {
            if (auto st = central_difference(j, perturb, evaluate, span, increment))
                return st;
            s.qdd = (s.qdd - z.d) / span;
            s.lambda = (s.lambda - z.dl) / span;
            if (k_.r() > 0)
                s.ydot = (z.rate_plus - z.rate_minus) / span;
            return GA_OK;
        };
        const double e = z.extrapolated_increment(j);
        ga_status st = pass(e);
        if (!st) {
            z.wide.swap(s);
            s.q.swap(z.wide.q);  // (the projected seeds stay)
            s.v.swap(z.wide.v);
            st = pass(0.5 * e);
        }
        k_.drop_step_matrix(true);  // another matrix, and a mass evaluated with p perturbed
        if (st) {
            k_.diag.append(" (sensitivity of the consistent start to parameter %d)", j);
            return st;
        }
        extrapolate(s.qdd, z.wide.qdd);
        extrapolate(s.lambda, z.wide.lambda);
        s.a = s.qdd;  // a_0 = qdd_0
        if (k_.r() > 0) {
            extrapolate(s.ydot, z.wide.ydot);
            s.y.setZero();
            s.w = s.ydot;  // w_0 = y'_0
        }
    }
    return GA_OK;
}

// The seeds (s.q, s.v) of parameter j onto the linearized position and velocity constraints
// at the start x: [I Phi_q^T; Phi_q 0] [dq; mu] = [dq0; -Phi_p], then [dv; mu] = [dv0; -Z dq
// - (Phi_q v + Phi_t)_p] with Z dq = d/de (Phi_q(q + e dq) v + Phi_t(q + e dq)) by central
// differences (the _p terms where the constraints depend on p_j).
ga_status ForwardSensitivity::project_seeds(const State &x, int j, StateDerivative &s)
{
    Sensitivities &z = sens;
    if (auto st = constraint_parameter_terms(j, x.t, x, true, false, x.t, x.q, x.lambda))
        return st;
    if (auto st = k_.factorize_tangent_projection(x.t, x.q)) {
        if (st != GA_ERR_SINGULAR)
            return st;
        return k_.diag.fail(GA_ERR_SINGULAR,
                            "cannot project the start's derivative: Phi_q is rank "
                            "deficient (rcond of [I Phi_q^T; Phi_q 0] = %.3g)",
                            k_.step_matrix_rcond());
    }
    z.rq = -s.q;
    z.rl = z.cl;
    k_.solve_tangent_projection(z.rq, z.rl, z.d, z.dl);
    s.q = z.d;
    z.rl = z.cv;
    const double s_max = s.q.lpNorm<Eigen::Infinity>();
    if (s_max > 0.0) {
        const double e = std::cbrt(kEps) * std::max(k_.model.space.max_magnitude(x.q), 1.0) / s_max;
        for (int side = 0; side < 2; ++side) {
            const double sign = side == 0 ? 1.0 : -1.0;
            k_.model.space.shifted(x.q, sign * e, s.q, z.xq);
            if (auto st = k_.model.jacobian(x.t, z.xq, z.J_pert))
                return st;
            if (auto st = k_.model.constraint_dt(x.t, z.xq, z.rv))
                return st;
            z.J_pert.multiply_add(1.0, x.v, z.rv);
            z.rl += (sign * 0.5 / e) * z.rv;
        }
    }
    z.rq = -s.v;
    k_.solve_tangent_projection(z.rq, z.rl, z.d, z.dl);
    s.v = z.d;
    return GA_OK;
}

// The state moved by `shift` times the derivative of parameter j (the quantities a step reads).
void ForwardSensitivity::shift_state(const State &from, const StateDerivative &s, double shift,
                                     State &to) const
{
    to.t = from.t;
    to.h_last = from.h_last;
    to.sliver_span = from.sliver_span;
    k_.model.space.shifted(from.q, shift, s.q, to.q);
    to.v = from.v + shift * s.v;
    to.qdd = from.qdd + shift * s.qdd;
    to.lambda = from.lambda + shift * s.lambda;
    to.a = from.a + shift * s.a;
    to.a_prev = from.a_prev;
    if (s.y.size() > 0) {
        to.y = from.y + shift * s.y;
        to.ydot = from.ydot + shift * s.ydot;
        to.w = from.w + shift * s.w;
        to.w_prev = from.w_prev;
    }
}

// The sensitivities' part of a commit, and of its undoing.
void ForwardSensitivity::on_commit()
{
    // The step's derivatives, where forward sensitivities computed them (an adjoint-only run
    // keeps the start's: its trial ones are scratch, NaN after a failed start, which the next
    // checkpoint carried and a restore refused)
    if (sens.forward)
        sens.accepted.swap(sens.trial);
}

void ForwardSensitivity::on_undo()
{
    if (sens.forward)
        sens.accepted.swap(sens.trial);
}

std::size_t ForwardSensitivity::checkpoint_size() const
{
    const std::size_t nv = static_cast<std::size_t>(k_.nv()), r = static_cast<std::size_t>(k_.r());
    return static_cast<std::size_t>(sens.np) * (4 * nv + static_cast<std::size_t>(k_.m()) + 3 * r);
}

void ForwardSensitivity::save_checkpoint(double *p) const
{
    for (const StateDerivative &d : sens.accepted)
        for (const Vec *x : {&d.q, &d.v, &d.qdd, &d.lambda, &d.a, &d.y, &d.ydot, &d.w}) {
            Eigen::Map<Vec>(p, x->size()) = *x;
            p += x->size();
        }
}

void ForwardSensitivity::load_checkpoint(const double *p)
{
    for (StateDerivative &d : sens.accepted)
        for (Vec *x : {&d.q, &d.v, &d.qdd, &d.lambda, &d.a, &d.y, &d.ydot, &d.w}) {
            *x = Eigen::Map<const Vec>(p, x->size());
            p += x->size();
        }
}

// Before an attempt: the starts that are not the linear map of the step before -- a Taylor
// step, a fresh start -- by differences of the start functions (forward); with the adjoint
// only, the record learns that its sweep does not cover them.
ga_status ForwardSensitivity::before_attempt(const StepPlan &plan, const State &accepted)
{
    sens.step_done = false;
    if (plan.kind == StepPlan::Sliver) {
        if (sens.forward)
            return by_differences(accepted, plan.h, true, false);
        sens.step_done = true;  // (adjoint only: recorded as a step not covered)
        return GA_OK;
    }
    sens.start_given = false;
    if (plan.fresh && (sens.forward || k_.start_pending()))
        return by_differences(accepted, plan.h, false, plan.restart_short);
    if (plan.fresh)
        sens.start_given = true;  // (adjoint only: recorded as a start not covered)
    return GA_OK;
}

// A fresh start (the first step's corrected starting values, a step after Taylor steps, a
// step far longer than the one before) or a Taylor step: their computations differenced along
// the derivative of the state and p_j. A Taylor step's derivative is that of the step; a
// start's is that of (v_n, a_n, qdd_n) as the step uses them.
ga_status ForwardSensitivity::by_differences(const State &accepted, double h, bool taylor_step,
                                             bool restart_short)
{
    for (int j = 0; j < sens.np; ++j) {
        StateDerivative &out = taylor_step ? sens.trial[j] : sens.start[j];
        const StateDerivative &s = sens.accepted[j];
        // The start functions run from the perturbed state, scratch_ (evaluate is called
        // between perturb(true) and perturb(false) only).
        const auto perturb = [&](bool on, double shift) {
            if (on)
                shift_state(accepted, s, shift, scratch_);
        };
        const auto evaluate = [&](int side) {
            if (auto st = taylor_step ? k_.sliver_step(scratch_, h)
                                      : k_.prepare_start(scratch_, h, restart_short))
                return st;
            const auto take = [side](Vec &to, const Vec &from) {
                if (side == 0)
                    to = from;
                else
                    to -= from;
            };
            if (taylor_step) {
                const State &trial = k_.trial();
                const ConfigurationSpace &space = k_.model.space;
                // d/dp of q is a tangent: on a group the central difference is
                // log(q_-^-1 q_+) (second order like the difference; storages do not subtract)
                if (space.euclidean())
                    take(out.q, trial.q);
                else if (side == 0)
                    sens.xq = trial.q;
                else
                    space.increment_between(trial.q, sens.xq, out.q);
                take(out.v, trial.v);
                take(out.qdd, trial.qdd);
                take(out.lambda, trial.lambda);
                take(out.a, trial.a);
                if (k_.r() > 0) {
                    take(out.y, trial.y);
                    take(out.ydot, trial.ydot);
                    take(out.w, trial.w);
                }
            } else {
                const Stepper::StepStart start = k_.step_start(scratch_);
                take(out.v, *start.v);
                take(out.a, *start.a);
                take(out.qdd, *start.qdd);
                if (k_.r() > 0) {
                    take(out.w, *start.w);
                    take(out.ydot, *start.ydot);
                }
            }
            return GA_OK;
        };
        // extrapolated differences (sensitivity_start)
        const bool first_order = k_.r() > 0;
        const auto fields = [&](StateDerivative &x) {
            std::array<Vec *, 8> f{&x.v, &x.a, &x.qdd, nullptr, nullptr, nullptr, nullptr, nullptr};
            if (first_order) {
                f[3] = &x.w;
                f[7] = &x.ydot;  // (of a start: its y' as the step uses it)
            }
            if (taylor_step) {
                f[4] = &x.q;
                f[5] = &x.lambda;
                if (first_order)
                    f[6] = &x.y;
            }
            return f;
        };
        const auto pass = [&](double increment) {
            double span = 0.0;
            if (auto st = central_difference(j, perturb, evaluate, span, increment))
                return st;
            for (Vec *f : fields(out))
                if (f)
                    *f /= span;
            return GA_OK;
        };
        const double e = sens.extrapolated_increment(j);
        ga_status st = pass(e);
        if (!st) {
            out.swap(sens.wide);
            st = pass(0.5 * e);
        }
        if (st) {
            k_.diag.append(" (sensitivity of the %s to parameter %d)",
                           taylor_step ? "short step" : "start of the step", j);
            return st;
        }
        const auto half = fields(out), wide = fields(sens.wide);
        for (std::size_t k = 0; k < half.size(); ++k)
            if (half[k])
                extrapolate(*half[k], *wide[k]);
    }
    if (taylor_step)
        sens.step_done = true;
    else
        sens.start_given = true;
    return GA_OK;
}

// R_p: the derivative of r^q = M qdd - f + Phi_q^T lambda in p_j at the converged step x,
// into sens.rq (added).
ga_status ForwardSensitivity::parameter_residual(int j, double t, const State &x)
{
    Sensitivities &z = sens;
    if (z.depends & GA_DEPENDS_FORCE) {
        if (k_.model.cb.force_p) {
            if (auto st = k_.model.force_p(t, x.q, x.v, j, z.f_plus))
                return st;
            z.rq -= z.f_plus;
        } else if (k_.model.has_force()) {
            double span = 0.0;
            const auto evaluate = [&](int side) {
                return k_.model.force(t, x.q, x.v, side == 0 ? z.f_plus : z.f_minus);
            };
            if (auto st = central_difference(
                    j, [](bool, double) {}, evaluate, span))
                return st;
            z.rq -= (z.f_plus - z.f_minus) / span;
        }
    }
    if (z.depends & GA_DEPENDS_MASS) {
        if (k_.model.cb.mass_p) {
            if (auto st = k_.model.mass_p(t, x.q, j, x.qdd, z.f_plus))
                return st;
            z.rq += z.f_plus;
        } else {
            double span = 0.0;
            z.f_plus.setZero();
            const auto evaluate = [&](int side) {
                if (auto st = k_.model.mass(t, x.q, z.M_pert))
                    return st;
                z.M_pert.multiply_add(side == 0 ? 1.0 : -1.0, x.qdd, z.f_plus);
                return GA_OK;
            };
            if (auto st = central_difference(
                    j, [](bool, double) {}, evaluate, span))
                return st;
            z.rq += z.f_plus / span;
        }
    }
    return GA_OK;
}

// d/dp_j of r^y = y' - g: -dg/dp_j by central differences of the rate (GA_DEPENDS_RATE), into
// sens.ry (added).
ga_status ForwardSensitivity::rate_parameter_residual(int j, double t, const State &x)
{
    Sensitivities &z = sens;
    if (!(z.depends & GA_DEPENDS_RATE))
        return GA_OK;
    double span = 0.0;
    const auto evaluate = [&](int side) {
        return k_.model.rate(t, x.q, x.v, x.y, side == 0 ? z.rate_plus : z.rate_minus);
    };
    if (auto st = central_difference(
            j, [](bool, double) {}, evaluate, span))
        return st;
    z.ry -= (z.rate_plus - z.rate_minus) / span;
    return GA_OK;
}

// The constraints' share of R_p (GA_DEPENDS_CONSTRAINT) at the converged step x: into sens.cq
// d/dp_j (Phi_q^T lambda), into sens.cl dPhi/dp_j and, with `velocity`, into sens.cv
// d/dp_j (Phi_q v + Phi_t); with `correction` (index 2) into sens.cbt the derivative of the
// position correction -B^T eta_bar, B = Phi_q(q_n) at t_n. Without that flag they stay the
// zeros they were allocated as.
ga_status ForwardSensitivity::constraint_parameter_terms(int j, double t, const State &x,
                                                         bool velocity, bool correction, double t_n,
                                                         const Vec &q_n, const Vec &eta)
{
    Sensitivities &z = sens;
    if (!(z.depends & GA_DEPENDS_CONSTRAINT) || k_.m() == 0)
        return GA_OK;
    for (Vec *c : {&z.cq, &z.cl, &z.cv, &z.cbt})
        c->setZero();
    ModelMatrix &Jp = z.J_pert;
    if (k_.model.cb.constraint_p) {
        if (auto st = k_.model.constraint_p(t, x.q, j, z.cl, Jp, velocity ? &z.cv : nullptr))
            return st;
        Jp.multiply_transpose_add(1.0, x.lambda, z.cq);
        if (velocity)
            Jp.multiply_add(1.0, x.v, z.cv);
        if (correction) {
            if (auto st = k_.model.constraint_p(t_n, q_n, j, z.phi, Jp, nullptr))
                return st;
            Jp.multiply_transpose_add(-1.0, eta, z.cbt);
        }
        return GA_OK;
    }
    // Extrapolated central differences, (4 D(e/2) - D(e)) / 3 with e = eps^(1/5) p_scale:
    // error O(eps^(4/5)), not eps^(2/3). In index 3 dPhi/dp enters dqdd/dp and dlambda/dp
    // divided by beta h^2.
    const auto evaluate = [&](int side) {
        const double sign = side == 0 ? 1.0 : -1.0;
        if (auto st = k_.model.constraint(t, x.q, z.phi))
            return st;
        z.cl += sign * z.phi;
        if (auto st = k_.model.jacobian(t, x.q, Jp))
            return st;
        Jp.multiply_transpose_add(sign, x.lambda, z.cq);
        if (velocity) {
            if (auto st = k_.model.constraint_dt(t, x.q, z.phi))
                return st;
            z.cv += sign * z.phi;
            Jp.multiply_add(sign, x.v, z.cv);
        }
        if (correction) {
            if (auto st = k_.model.jacobian(t_n, q_n, Jp))
                return st;
            Jp.multiply_transpose_add(-sign, eta, z.cbt);
        }
        return GA_OK;
    };
    Vec *terms[] = {&z.cq, &z.cl, &z.cv, &z.cbt}, *wide[] = {&z.cq2, &z.cl2, &z.cv2, &z.cbt2};
    const double e = z.extrapolated_increment(j);
    double span = 0.0, half = 0.0;
    if (auto st = central_difference(
            j, [](bool, double) {}, evaluate, span, e))
        return st;
    for (int k = 0; k < 4; ++k) {
        wide[k]->swap(*terms[k]);
        terms[k]->setZero();
    }
    if (auto st = central_difference(
            j, [](bool, double) {}, evaluate, half, 0.5 * e))
        return st;
    for (int k = 0; k < 4; ++k)
        *terms[k] = (4.0 / (3.0 * half)) * *terms[k] - (1.0 / (3.0 * span)) * *wide[k];
    return GA_OK;
}

// -d/dq (Phi_q(q)^T eta) s at (t, q), into out: central differences of Phi_q. Index 2: the
// position correction -B^T eta_bar uses B = Phi_q(q_n) of the step's start. The matrix
// d/dq (Phi_q^T eta) is symmetric (second derivatives of eta^T Phi), so this also applies its
// transpose (adjoint.cpp).
ga_status ForwardSensitivity::correction_derivative(double t, const Vec &q, const Vec &eta,
                                                    const Vec &s, Vec &out)
{
    Sensitivities &z = sens;
    out.setZero();
    const double s_max = s.lpNorm<Eigen::Infinity>();
    if (s_max == 0.0)
        return GA_OK;
    const double e = std::cbrt(kEps) * std::max(k_.model.space.max_magnitude(q), 1.0) / s_max;
    for (int side = 0; side < 2; ++side) {
        k_.model.space.shifted(q, side == 0 ? e : -e, s, z.q_pert);
        if (auto st = k_.model.jacobian(t, z.q_pert, z.J_pert))
            return st;
        z.J_pert.multiply_transpose_add(side == 0 ? -0.5 / e : 0.5 / e, eta, out);
    }
    return GA_OK;
}

// After a step converged (trial_ holds it), the derivatives of its state.
ga_status ForwardSensitivity::step(double h)
{
    if (!sens.active() || !sens.forward || sens.step_done)
        return GA_OK;
    const State &s = k_.state();
    const State &x = k_.trial();
    const Params &p = k_.params;
    const NewtonCoefficients c = newton_coefficients(p, h);
    const bool index2 = k_.formulation == GA_INDEX2_STABILIZED;
    const double t1 = x.t;

    // The exact iteration matrix at the converged step: every tangent, whatever the option,
    // and where they come by differences, central ones (their error enters dqdd and dlambda
    // at full size; a kept matrix is of an older iterate). The next step's Newton iteration
    // starts with it.
    bool K = false, C = false, Z = false;
    ga_status st = k_.factorize_exact(x, h, K, C, Z);
    if (st) {
        k_.diag.append(" (the exact iteration matrix for the sensitivities)");
        return st;
    }
    const Stepper::StepStart start = k_.step_start(s);
    Sensitivities &z = sens;
    for (int j = 0; j < z.np; ++j) {
        const StateDerivative &sn = z.accepted[j];
        StateDerivative &s1 = z.trial[j];
        // the start of the step as the step used it (attempt_step)
        const Vec &sv = z.start_given ? z.start[j].v : sn.v;
        const Vec &sqdd = z.start_given ? z.start[j].qdd : sn.qdd;
        const Vec *sa = &sn.a;
        if (z.start_given) {
            sa = &z.start[j].a;
        } else if (start.a_rescaled) {  // a_n rescaled to h
            z.a0 = sn.qdd + (h / s.h_last) * (sn.a - sn.qdd);
            sa = &z.a0;
        }
        // first-order states: the w the step started from, and the predictor with y' = 0
        const FirstOrderParams &p1 = k_.params1;
        const Vec *sw = &sn.w;
        const Vec &sydot = z.start_given ? z.start[j].ydot : sn.ydot;
        if (k_.r() > 0) {
            if (z.start_given) {
                sw = &z.start[j].w;
            } else if (start.w_rescaled) {  // w_n rescaled to h (first_order_start)
                z.w0 = sn.ydot + (h / s.h_last) * (sn.w - sn.ydot);
                sw = &z.w0;
            }
            s1.ydot.setZero();
            s1.w = (p1.alpha_f * sydot - p1.alpha_m * *sw) / (1.0 - p1.alpha_m);
            s1.y = sn.y + h * ((1.0 - p1.gamma) * *sw + p1.gamma * s1.w);
        }
        // predictor, eqs. (3)-(5) with qdd_{n+1} = 0
        s1.qdd.setZero();
        s1.lambda.setZero();
        s1.a = (p.alpha_f * sqdd - p.alpha_m * *sa) / (1.0 - p.alpha_m);
        const ConfigurationSpace &space = k_.model.space;
        space.newmark_derivative(s.q, x.q, sn.q, sv, *sa, s1.a, h, p.beta, s1.q);
        s1.v = sv + h * ((1.0 - p.gamma) * *sa + p.gamma * s1.a);
        // the constraints' parameter terms (zero unless they depend on p)
        if ((st = constraint_parameter_terms(j, t1, x, index2, index2, k_.B_time(), s.q,
                                             k_.eta_bar()))) {
            k_.diag.append(" (derivative of the constraints in parameter %d)", j);
            return st;
        }
        if (index2 && k_.m() > 0) {
            if ((st = correction_derivative(k_.B_time(), s.q, k_.eta_bar(), sn.q, z.bt)))
                return st;
            space.tangent_increment(s.q, x.q, z.bt, s1.q);
            space.tangent_increment(s.q, x.q, z.cbt, s1.q);
        }
        // the residual linearized at the converged step
        z.rq = z.cq;
        if ((st = parameter_residual(j, t1, x))) {
            k_.diag.append(" (derivative of the residual in parameter %d)", j);
            return st;
        }
        if (K)
            k_.stiffness_matrix().multiply_add(1.0, s1.q, z.rq);
        if (C)
            k_.damping_matrix().multiply_add(1.0, s1.v, z.rq);
        const CouplingBlocks &b = k_.coupling();
        if (k_.r() > 0) {  // r^q sees y through f; r^y = y' - g(t, q, v, y)
            z.rq.noalias() -= b.f_y * s1.y;
            z.ry = s1.ydot;
            z.ry.noalias() -= b.g_q * s1.q;
            z.ry.noalias() -= b.g_v * s1.v;
            z.ry.noalias() -= b.g_y * s1.y;
            if ((st = rate_parameter_residual(j, t1, x)))
                return st;
        }
        z.rl = z.cl;
        k_.jacobian_matrix().multiply_add(1.0, s1.q, z.rl);
        if (index2) {
            z.rv = z.cv;
            if (Z) {
                k_.Z_matrix().multiply_add(1.0, s1.q, z.rv);
                if (!space.euclidean() && !k_.Z_matrix().dense()) {
                    // on a pattern Z is the difference alone: Phi_q [s, v] added here, as the
                    // step matrix adds it (Model::velocity_constraint_tangent)
                    space.bracket(s1.q, x.v, z.bracket);
                    k_.jacobian_matrix().multiply_add(1.0, z.bracket, z.rv);
                }
            }
            k_.jacobian_matrix().multiply_add(1.0, s1.v, z.rv);
        }
        k_.solve_step_matrix(z.rq, z.rl, z.rv, h, z.d, z.w, z.dl, z.e);
        if (k_.r() > 0) {  // elimination onto y (first_order.cpp): dy, then x0 - Z dy
            z.gy = -z.ry;
            z.gy.noalias() += k_.coupling_q_step() * z.d;
            z.gy.noalias() += c.gamma_prime * (b.g_v * (index2 ? z.w : z.d));
            k_.eliminate_first_order(z.gy, z.dy, z.d, z.dl, z.w);
            s1.y += z.dy;
            s1.ydot = first_order_newton_coefficient(p1, h) * z.dy;
            s1.w = (p1.alpha_f * sydot - p1.alpha_m * *sw + (1.0 - p1.alpha_f) * s1.ydot) /
                   (1.0 - p1.alpha_m);
        }
        const Vec &dw = index2 ? z.w : z.d;
        space.tangent_increment(s.q, x.q, z.d, s1.q);
        s1.v += c.gamma_prime * dw;
        s1.qdd += c.beta_prime * dw;
        s1.lambda = z.dl;
        s1.a =
            (p.alpha_f * sqdd - p.alpha_m * *sa + (1.0 - p.alpha_f) * s1.qdd) / (1.0 - p.alpha_m);
        if (!all_finite(s1.q) || !all_finite(s1.v) || !all_finite(s1.qdd) || !all_finite(s1.lambda))
            return k_.diag.fail(GA_ERR_NONFINITE,
                                "the sensitivity to parameter %d is not finite after the step "
                                "from t = %.17g with h = %g",
                                j, s.t, h);
    }
    return GA_OK;
}

}  // namespace ga
