// ga::ConfigurationSpace: the one place that knows how q moves. Every site that updates,
// interpolates, perturbs or measures q goes through it, so that a q that is not a vector of
// v's length changes this file and the matrix assembly, not the step, the error control, the
// sensitivities or the adjoint.
//
// The space of ga_create is one block R^n: each body below is then the expression the solver
// had inline at its site, verbatim and evaluated in the same order, so that every result is
// bit for bit the same (test_golden). The segment forms serve the step's fused kBlock loops;
// they take Eigen segments and build the same expression trees the loops built.
//
// The space of ga_create_space is a product of blocks: R^k, and rotations SO(3) stored as unit
// quaternions (4 numbers) or rotation matrices (9, column-major), with right increments and
// body-frame velocities, q o exp(psi) (docs/algorithms.md sec. 14). Its bodies are in
// configuration_space.cpp; the step takes per-block paths for it (no fused loops: q and v
// are not indexed alike).
//
// Vocabulary: q has nq() coordinates; v, qdd, a, f, the rows of M, C, K and the columns of
// Phi_q, and every increment of q (Newton's dq, a projection's step, a difference's direction,
// a sensitivity's s_q) have nv(). In R^n, nq() == nv().
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "types.hpp"

namespace ga {

class ConfigurationSpace {
public:
    // Pose: SE(3), a position and a quaternion (7 numbers), a twist (u, w) in v
    enum class Kind : unsigned char { Vector, Quaternion, Matrix, Pose };
    struct Block {
        Kind kind;
        Eigen::Index nv;  // v's coordinates: 3 for a rotation, 6 for a pose
    };
    // Storage of one block's q
    static Eigen::Index stored(Kind kind, Eigen::Index nv)
    {
        return kind == Kind::Vector ? nv
               : kind == Kind::Quaternion ? 4
               : kind == Kind::Matrix     ? 9
                                          : 7;
    }
    static Eigen::Index stored(const Block &b) { return stored(b.kind, b.nv); }

    explicit ConfigurationSpace(Eigen::Index n) : nq_(n), nv_(n) {}
    // The product of the blocks in order; of vector blocks only, R^n (the space above).
    explicit ConfigurationSpace(const std::vector<Block> &blocks);

    Eigen::Index nq() const { return nq_; }
    Eigen::Index nv() const { return nv_; }
    bool euclidean() const { return parts_.empty(); }
    // The group blocks (rotations and poses), numbered 0, 1, ... in order
    Eigen::Index rotations() const { return rotations_; }

    // ---- group blocks (configuration_space.cpp); never called on R^n ----
    // xi = h v_n + h^2 ((1/2 - beta) a_n + beta a): eq. (4)'s increment, on a segment of v
    template <class Out, class V, class A0, class A1>
    static void newmark_increment(Out &&xi, const V &v_n, const A0 &a_n, const A1 &a, double h,
                                  double beta)
    {
        xi = h * v_n + (h * h) * ((0.5 - beta) * a_n + beta * a);
    }
    // q = q_n (+) xi, block by block (q_n o exp(xi) on a rotation): the step's q from its
    // increment, recomputed at every iterate (composing Newton's corrections one by one would
    // add the tangent operator's error to each)
    void step_to(const Vec &q_n, const Vec &xi, Vec &q) const;
    // out += c (u x g) on each rotation's coordinates (vector blocks: nothing)
    void add_cross(double c, const Vec &u, const Vec &g, Vec &out) const;
    // xi with q_n1 = q_n (+) xi (log(q_n^-1 q_n1) on a rotation): a recorded step's increment
    void increment_between(const Vec &q_n, const Vec &q_n1, Vec &xi) const;
    // A <- A T(xi) on the columns of the rotations (rows x nv, column-major with leading
    // dimension ld): the q-columns of K_t and Phi_q in the iteration matrix (sec. 14)
    void right_multiply_tangent(const Vec &xi, double *A, Eigen::Index rows,
                                Eigen::Index ld) const;
    // The group block (0, 1, ... in order) that v coordinate j belongs to, and j's place in
    // it in *local; -1 for a vector coordinate. (The sparse path's expanded patterns.)
    int rotation_of(Eigen::Index j, int *local) const;
    // The first v coordinate of group block r, and its width (3 or 6)
    Eigen::Index rotation_start(int r) const { return parts_[rotation_part_[r]].v0; }
    int rotation_width(int r) const { return static_cast<int>(parts_[rotation_part_[r]].nv); }
    // T(xi) of every group block in order, width^2 numbers each, row-major, into T
    void rotation_tangents(const Vec &xi, double *T) const;
    // Z <- Z + J ad(., v) on the rotations' columns (J, Z: rows x nv, column-major, ld =
    // rows): Z w += J [w, v] with [w, v] = w x v on each rotation
    void add_bracket(const Vec &v, const double *J, Eigen::Index rows, double *Z) const;
    // The same on a vector: u = [w, v] = -ad(v) w on every group block, 0 elsewhere (Phi_q u
    // is what add_bracket adds to Z w)
    void bracket(const Vec &w, const Vec &v, Vec &u) const;
    // Its transpose: out += (-ad(v))^T u on every group block
    void bracket_transpose_add(const Vec &v, const Vec &u, Vec &out) const;
    // The same bracket for matrices on patterns: -ad(v) T(xi) (xi null: -ad(v)) of every group
    // block, laid out as rotation_tangents (TangentProduct::add_bracket scatters J by them)
    void rotation_brackets(const Vec &v, const Vec *xi, double *G) const;
    // The first rotation block whose storage is not a rotation (a quaternion's norm, a
    // matrix's orthonormality or determinant off by more than 1e-6), as the index of its
    // first coordinate in q (a pose's quaternion's); -1 if none.
    Eigen::Index invalid_rotation(const double *q) const;
    // Storage accepted by invalid_rotation but more than `exact` off a rotation, made one (a
    // quaternion normalized, a matrix's nearest rotation): else the state's rotations would
    // stay 1e-6 off, and a checkpoint of it could drift past the check that accepted it.
    // Closer storage is left bit for bit as it is. ga_init takes 1e-10 (kInitExact); a
    // restore 1e-8 (kRestoreExact), far above a solver's own states: ga_init's 1e-10, turned
    // by the steps (at most tripled), plus round-off.
    static constexpr double kInitExact = 1e-10, kRestoreExact = 1e-8;
    void normalize_rotations(double *q, double exact) const;

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
    void increment(Vec &q, const Vec &dq) const
    {
        if (euclidean())
            q += dq;
        else
            group_retract(q, 1.0, dq, q);
    }

    // out = q (+) (h v + h^2/2 qdd): the Taylor steps (slivers, starting values)
    void taylor(const Vec &q, const Vec &v, const Vec &qdd, double h, Vec &out) const
    {
        if (euclidean())
            out = q + h * v + (0.5 * h * h) * qdd;
        else
            group_taylor(q, v, qdd, h, out);
    }

    // out = q (+) e w: a directional difference's point
    void shifted(const Vec &q, double e, const Vec &w, Vec &out) const
    {
        if (euclidean())
            out = q + e * w;
        else
            group_retract(q, e, w, out);
    }
    // q_pert = q (+) e e_j in coordinate j, and back: column differences (q_pert == q outside j)
    // (On a rotation, q's block o exp(e e_j) into q_pert: a second shift in the same block
    // replaces the first, so column groups never hold two columns of one rotation -- group
    // spaces take no patterns; restoring copies the whole block back.)
    void shift_coordinate(Vec &q_pert, const Vec &q, Eigen::Index j, double e) const
    {
        if (euclidean())
            q_pert[j] = q[j] + e;
        else
            group_shift(q_pert, q, j, e);
    }
    void restore_coordinate(Vec &q_pert, const Vec &q, Eigen::Index j) const
    {
        if (euclidean())
            q_pert[j] = q[j];
        else
            group_restore(q_pert, q, j);
    }

    // cubic Hermite interpolation of q over a step of length h from (q_a, v_a) to (q_b, v_b),
    // with the basis values h00, h10, h01, h11 at the point; on a rotation, q_a o exp(p) with
    // p the Hermite curve in the algebra from 0 to xi = log(q_a^-1 q_b), p' = h v_a at the
    // start and h T(xi)^-1 v_b at the end (sec. 14)
    void hermite(const Vec &q_a, const Vec &v_a, const Vec &q_b, const Vec &v_b, double h,
                 double h00, double h10, double h01, double h11, Vec &out) const
    {
        if (euclidean())
            out = h00 * q_a + (h10 * h) * v_a + h01 * q_b + (h11 * h) * v_b;
        else
            group_hermite(q_a, v_a, q_b, v_b, h, h00, h10, h01, h11, out);
    }

    // The size of q where tolerances and round-off floors scale with it: per increment
    // coordinate i, and the largest (0 for an empty q)
    // (a rotation's coordinates: 1, the radian its angles are measured against)
    double magnitude(const Vec &q, Eigen::Index i) const
    {
        return euclidean() ? std::fabs(q[i]) : group_magnitude(q, i);
    }
    template <class Q>
    double max_magnitude(const Q &q) const
    {
        const double top = q.size() == 0 ? 0.0 : q.cwiseAbs().maxCoeff();
        return rotations_ > 0 ? std::max(top, 1.0) : top;
    }
    // |q_1 (-) q_0| in increment coordinate i (on a rotation, of log(q_0^-1 q_1))
    double distance(const Vec &q1, const Vec &q0, Eigen::Index i) const
    {
        return euclidean() ? std::fabs(q1[i] - q0[i]) : group_distance(q1, q0, i);
    }

    // ---- tangent vectors across a step from q_n to q_n1 (docs/algorithms.md sec. 14) ----
    // The derivatives of the discrete map (the forward sensitivities' linear step and,
    // transposed, the adjoint's): on a group, with xi = log(q_n^-1 q_n1), a tangent vector at
    // q_n reaches q_n1 transported by the adjoint representation of exp(-xi), and an increment
    // of xi enters through the tangent operator T(xi); in R^n both are identities.
    // The derivative of eq. (4) along a derivative of the state: s_q transported, plus
    // h s_v + h^2 ((1/2 - beta) s_a + beta s_a1) through T.
    void newmark_derivative(const Vec &q_n, const Vec &q_n1, const Vec &s_q, const Vec &s_v,
                            const Vec &s_a, const Vec &s_a1, double h, double beta,
                            Vec &out) const
    {
        if (euclidean())
            out = s_q + h * s_v + (h * h) * ((0.5 - beta) * s_a + beta * s_a1);
        else
            group_newmark_derivative(q_n, q_n1, s_q, s_v, s_a, s_a1, h, beta, out);
    }
    // s_q += T(xi) d: an increment of the step's xi added to a derivative of q_n1
    void tangent_increment(const Vec &q_n, const Vec &q_n1, const Vec &d, Vec &s_q) const
    {
        if (euclidean())
            s_q += d;
        else
            group_tangent(q_n, q_n1, d, s_q, false);
    }
    // The transposes, in place on an adjoint variable at q_n1: of the transport (to q_n) and
    // of T(xi).
    void transport_transpose(const Vec &q_n, const Vec &q_n1, Vec &m) const
    {
        if (!euclidean())
            group_transport_transpose(q_n, q_n1, m);
    }
    void tangent_transpose(const Vec &q_n, const Vec &q_n1, Vec &m) const
    {
        if (!euclidean())
            group_tangent(q_n, q_n1, m, m, true);
    }

private:
    // A block placed: its kind and where its coordinates start in q and in v
    struct Part {
        Kind kind;
        Eigen::Index q0, v0, nv;
    };
    void group_retract(const Vec &q, double e, const Vec &w, Vec &out) const;
    void group_taylor(const Vec &q, const Vec &v, const Vec &qdd, double h, Vec &out) const;
    void group_shift(Vec &q_pert, const Vec &q, Eigen::Index j, double e) const;
    void group_restore(Vec &q_pert, const Vec &q, Eigen::Index j) const;
    void group_hermite(const Vec &q_a, const Vec &v_a, const Vec &q_b, const Vec &v_b, double h,
                       double h00, double h10, double h01, double h11, Vec &out) const;
    double group_magnitude(const Vec &q, Eigen::Index i) const;
    void group_newmark_derivative(const Vec &q_n, const Vec &q_n1, const Vec &s_q,
                                  const Vec &s_v, const Vec &s_a, const Vec &s_a1, double h,
                                  double beta, Vec &out) const;
    // out += T(xi) d, or with transposed: out = T(xi)^T d (out may be d)
    void group_tangent(const Vec &q_n, const Vec &q_n1, const Vec &d, Vec &out,
                       bool transposed) const;
    void group_transport_transpose(const Vec &q_n, const Vec &q_n1, Vec &m) const;
    double group_distance(const Vec &q1, const Vec &q0, Eigen::Index i) const;
    const Part &part_of(Eigen::Index i) const { return parts_[part_of_[i]]; }

    Eigen::Index nq_, nv_;
    Eigen::Index rotations_ = 0;
    std::vector<Part> parts_;     // empty: R^n
    std::vector<int> part_of_;    // v coordinate -> its part (group spaces only)
    std::vector<int> rotation_part_;  // rotation r -> its part
};

}  // namespace ga
