// ga::ConfigurationSpace: the one place that knows how q moves. Every site that updates,
// interpolates, perturbs or measures q goes through it, so that a q that is not a vector of
// v's length (a Lie group, docs/algorithms.md sec. 14) changes this file and the matrix
// assembly, not the step, the error control, the sensitivities or the adjoint.
//
// Today the space is one block R^n: each body below is the expression the solver had inline at
// its site, verbatim and evaluated in the same order, so that every result is bit for bit the
// same (test_golden). The segment forms serve the step's fused kBlock loops; they take Eigen
// segments and build the same expression trees the loops built.
//
// Vocabulary: q has nq() coordinates; v, qdd, a, f, the rows of M, C, K and the columns of
// Phi_q, and every increment of q (Newton's dq, a projection's step, a difference's direction,
// a sensitivity's s_q) have nv(). In R^n, nq() == nv().
#pragma once

#include <cmath>

#include "types.hpp"

namespace ga {

class ConfigurationSpace {
public:
    explicit ConfigurationSpace(Eigen::Index n) : nq_(n), nv_(n) {}

    Eigen::Index nq() const { return nq_; }
    Eigen::Index nv() const { return nv_; }
    bool euclidean() const { return true; }

    // eq. (4) on a segment: q = q_n + h v_n + h^2 ((1/2 - beta) a_n + beta a)
    template <class Out, class Q, class V, class A0, class A1>
    void newmark(Out &&q, const Q &q_n, const V &v_n, const A0 &a_n, const A1 &a, double h,
                 double beta) const
    {
        q = q_n + h * v_n + (h * h) * ((0.5 - beta) * a_n + beta * a);
    }

    // q <- q (+) dq: Newton's correction (eq. 7) and a projection's Gauss-Newton step
    template <class Q, class D>
    void increment(Q &&q, const D &dq) const
    {
        q += dq;
    }

    // out = q (+) (h v + h^2/2 qdd): the Taylor steps (slivers, starting values)
    void taylor(const Vec &q, const Vec &v, const Vec &qdd, double h, Vec &out) const
    {
        out = q + h * v + (0.5 * h * h) * qdd;
    }

    // out = q (+) e w: a directional difference's point
    template <class Out>
    void shifted(const Vec &q, double e, const Vec &w, Out &out) const
    {
        out = q + e * w;
    }
    // q_pert = q (+) e e_j in coordinate j, and back: column differences (q_pert == q outside j)
    void shift_coordinate(Vec &q_pert, const Vec &q, Eigen::Index j, double e) const
    {
        q_pert[j] = q[j] + e;
    }
    void restore_coordinate(Vec &q_pert, const Vec &q, Eigen::Index j) const
    {
        q_pert[j] = q[j];
    }

    // cubic Hermite interpolation of q over a step of length h from (q_a, v_a) to (q_b, v_b),
    // with the basis values h00, h10, h01, h11 at the point
    void hermite(const Vec &q_a, const Vec &v_a, const Vec &q_b, const Vec &v_b, double h,
                 double h00, double h10, double h01, double h11, Vec &out) const
    {
        out = h00 * q_a + (h10 * h) * v_a + h01 * q_b + (h11 * h) * v_b;
    }

    // The size of q where tolerances and round-off floors scale with it: per increment
    // coordinate i, and the largest (0 for an empty q)
    double magnitude(const Vec &q, Eigen::Index i) const { return std::fabs(q[i]); }
    template <class Q>
    double max_magnitude(const Q &q) const
    {
        return q.size() == 0 ? 0.0 : q.cwiseAbs().maxCoeff();
    }
    // |q_1 (-) q_0| in increment coordinate i
    double distance(const Vec &q1, const Vec &q0, Eigen::Index i) const
    {
        return std::fabs(q1[i] - q0[i]);
    }

    // ---- tangent vectors across a step from q_n to q_n1 (docs/algorithms.md sec. 14) ----
    // The derivatives of the discrete map (the forward sensitivities' linear step and,
    // transposed, the adjoint's): on a group, with xi = log(q_n^-1 q_n1), a tangent vector at
    // q_n reaches q_n1 transported by the adjoint representation of exp(-xi), and an increment
    // of xi enters through the tangent operator T(xi); in R^n both are identities.
    // The derivative of eq. (4) along a derivative of the state: s_q transported, plus
    // h s_v + h^2 ((1/2 - beta) s_a + beta s_a1) through T.
    void newmark_derivative(const Vec & /*q_n*/, const Vec & /*q_n1*/, const Vec &s_q,
                            const Vec &s_v, const Vec &s_a, const Vec &s_a1, double h,
                            double beta, Vec &out) const
    {
        out = s_q + h * s_v + (h * h) * ((0.5 - beta) * s_a + beta * s_a1);
    }
    // s_q += T(xi) d: an increment of the step's xi added to a derivative of q_n1
    void tangent_increment(const Vec & /*q_n*/, const Vec & /*q_n1*/, const Vec &d,
                           Vec &s_q) const
    {
        s_q += d;
    }
    // The transposes, in place on an adjoint variable at q_n1: of the transport (to q_n) and
    // of T(xi).
    void transport_transpose(const Vec & /*q_n*/, const Vec & /*q_n1*/, Vec & /*m*/) const {}
    void tangent_transpose(const Vec & /*q_n*/, const Vec & /*q_n1*/, Vec & /*m*/) const {}

private:
    Eigen::Index nq_, nv_;
};

}  // namespace ga
