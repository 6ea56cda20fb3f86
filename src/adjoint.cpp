// The discrete adjoint of the steps taken (docs/algorithms.md sec. 11). A recorded run is the
// composition of the maps sensitivity.cpp differentiates: per step the predictor P, the
// residual linearized at the converged step, the solve with the exact iteration matrix S and
// the update U of eq. (7). The sweep applies their transposes in reverse order, step by step
// from the last: U^T, then S^{-T} (its own factorization of S, assembled again at the recorded
// state: a transposed solve), then the transposed tangents K^T, C^T, Phi_q^T (and Z^T in
// index 2), then P^T -- one transposed solve per step, whatever the number of parameters.
// The parameters enter through R_p of each step and the start's derivatives.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/SparseCore>

#include "linear/klu_system.hpp"
#include "solver.hpp"

namespace ga {

void AdjointRecord::allocate(int nq_, int nv_, int m_, int r_, int np, long capacity_)
{
    nq = nq_;
    nv = nv_;
    m = m_;
    r = r_;
    capacity = capacity_;
    max_steps = capacity_;
    steps = 0;
    base = 0;
    interval = 0;
    unsupported_at = -1;
    data.assign((static_cast<std::size_t>(capacity_) + 1) * stride(), 0.0);
    for (auto *set : {&sigma0, &start0}) {
        set->resize(np);
        for (StateDerivative &x : *set)
            x.allocate(nv_, m_, r_);
    }
}

void AdjointRecord::allocate_checkpointed(int nq_, int nv_, int m_, int r_, int np, long interval_,
                                          long count, std::size_t state_size)
{
    const long full = max_steps;
    allocate(nq_, nv_, m_, r_, np, interval_);
    max_steps = full;
    interval = interval_;
    capacity = interval_ * count;
    checkpoint_size = state_size;
    checkpoints.assign(static_cast<std::size_t>(count) * state_size, 0.0);
    log.assign(static_cast<std::size_t>(capacity) * kLog, 0.0);
}

ga_status Adjoint::set_checkpoints(long interval, long count)
{
    // (interval * count fits in a long: the C API checked it)
    const std::size_t stride = AdjointRecord::stride_for(k_.nq(), k_.nv(), k_.m(), k_.r());
    if (interval > 0 && !fits_doubles(static_cast<std::size_t>(interval) + 1, stride))
        return k_.diag.fail(GA_ERR_NOMEM,
                            "an adjoint segment of interval = %ld steps (%zu doubles "
                            "each) is larger than memory can hold",
                            interval, stride);
    if (interval > 0 && !fits_doubles(static_cast<std::size_t>(count), run_.state_size()))
        return k_.diag.fail(GA_ERR_NOMEM,
                            "count = %ld adjoint checkpoints of %zu doubles each are "
                            "more than memory can hold",
                            count, run_.state_size());
    if (interval > 0 &&
        !fits_doubles(static_cast<std::size_t>(interval) * static_cast<std::size_t>(count),
                      AdjointRecord::kLog))
        return k_.diag.fail(GA_ERR_NOMEM,
                            "the step log of interval * count = %ld adjoint steps "
                            "(%zu doubles each) is larger than memory can hold",
                            interval * count, AdjointRecord::kLog);
    AdjointRecord record;  // built aside: a failed allocation leaves the one before
    record.max_steps = record_.max_steps;
    if (interval > 0)
        record.allocate_checkpointed(k_.nq(), k_.nv(), k_.m(), k_.r(), forward_.sens.np, interval,
                                     count, run_.state_size());
    else
        record.allocate(k_.nq(), k_.nv(), k_.m(), k_.r(), forward_.sens.np, record_.max_steps);
    record_ = std::move(record);
    return GA_OK;
}

ga_status Adjoint::set_method(int methods, long max_steps)
{
    const std::size_t stride = AdjointRecord::stride_for(k_.nq(), k_.nv(), k_.m(), k_.r());
    if ((methods & GA_SENSITIVITY_ADJOINT) &&
        !fits_doubles(static_cast<std::size_t>(max_steps) + 1, stride))
        return k_.diag.fail(GA_ERR_NOMEM,
                            "an adjoint record of max_steps = %ld steps (%zu doubles "
                            "each) is larger than memory can hold; ga_set_adjoint_checkpoints "
                            "keeps one segment",
                            max_steps, stride);
    AdjointRecord record;  // built aside: a failed allocation leaves the one before
    if (methods & GA_SENSITIVITY_ADJOINT)
        record.allocate(k_.nq(), k_.nv(), k_.m(), k_.r(), forward_.sens.np, max_steps);
    record_ = std::move(record);
    forward_.sens.forward = (methods & GA_SENSITIVITY_FORWARD) != 0;
    forward_.sens.adjoint = (methods & GA_SENSITIVITY_ADJOINT) != 0;
    return GA_OK;
}

namespace {
void put(const Vec &x, double *&out)
{
    Eigen::Map<Vec>(out, x.size()) = x;
    out += x.size();
}
}  // namespace

// A step converged (before its commit): room for it, and how it began (on_commit logs it).
ga_status Adjoint::on_converged(double h)
{
    const State &s = k_.state();
    AdjointRecord &r = record_;
    if (r.steps >= r.capacity && r.interval > 0)
        return k_.diag.fail(GA_ERR_NOMEM,
                            "the adjoint record is full (%ld steps: interval "
                            "= %ld times %ld checkpoints, ga_set_adjoint_checkpoints)",
                            r.capacity, r.interval, r.capacity / r.interval);
    if (r.steps >= r.capacity)
        return k_.diag.fail(GA_ERR_NOMEM,
                            "the adjoint record is full (max_steps = %ld: "
                            "ga_set_sensitivity_method)",
                            r.capacity);
    r.pending_rho = 1.0;
    if (forward_.sens.step_done || (forward_.sens.start_given && !k_.start_pending())) {
        r.pending_kind = AdjointRecord::Unsupported;
    } else if (forward_.sens.start_given) {
        r.pending_kind = AdjointRecord::First;
    } else {
        r.pending_kind = AdjointRecord::Regular;
        if (k_.step_start(s).a_rescaled)
            r.pending_rho = h / s.h_last;
    }
    return GA_OK;
}

void Adjoint::started()
{
    AdjointRecord &r = record_;
    const State &x = k_.state();
    r.steps = 0;
    r.base = 0;
    r.unsupported_at = -1;
    if (r.interval > 0)
        run_.get_state(r.checkpoint(0));
    double *e = r.entry(0);
    e[0] = x.t;
    e[1] = e[2] = e[3] = 0.0;
    e += 4;
    for (const Vec *v : {&x.q, &x.v, &x.qdd, &x.lambda})
        put(*v, e);
    Eigen::Map<Vec>(e, k_.m()).setZero();
    e += k_.m();
    put(x.y, e);
    put(x.ydot, e);
    for (int j = 0; j < forward_.sens.np; ++j) {
        const StateDerivative &s = forward_.sens.accepted[j];
        StateDerivative &d = r.sigma0[j];
        d.q = s.q;
        d.v = s.v;
        d.qdd = s.qdd;
        d.lambda = s.lambda;
        d.a = s.a;
        d.y = s.y;
        d.ydot = s.ydot;
        d.w = s.w;
    }
}

void Adjoint::on_commit()
{
    AdjointRecord &r = record_;
    const State &x = k_.state();
    const long k = ++r.steps;
    if (r.interval > 0 && k - r.base > r.interval) {  // a new segment starts at step k - 1
        std::copy_n(r.entry(k - 1), r.stride(), r.data.data());
        r.base = k - 1;
    }
    double *e = r.entry(k);
    e[0] = x.t;
    e[1] = x.h_last;
    e[2] = r.pending_rho;
    e[3] = r.pending_kind;
    if (r.interval > 0) {
        double *l = r.log_entry(k);
        std::copy_n(e, 4, l);
        const StepReport &report = k_.last_report();  // of the attempt accepted
        l[4] = report.plan.tol;
        l[5] = (report.plan.sliver_allowed ? 1.0 : 0.0) + (report.adaptive ? 2.0 : 0.0);
        std::copy_n(report.reuse_before, kReuseStateSize, l + 6);
    }
    e += 4;
    for (const Vec *v : {&x.q, &x.v, &x.qdd, &x.lambda})
        put(*v, e);
    if (k_.formulation == GA_INDEX2_STABILIZED)
        Eigen::Map<Vec>(e, k_.m()) = k_.eta_bar();
    else
        Eigen::Map<Vec>(e, k_.m()).setZero();
    e += k_.m();
    put(x.y, e);
    put(x.ydot, e);
    if (r.pending_kind == AdjointRecord::First)
        for (int j = 0; j < forward_.sens.np; ++j) {
            r.start0[j].v = forward_.sens.start[j].v;
            r.start0[j].a = forward_.sens.start[j].a;
            r.start0[j].qdd = forward_.sens.start[j].qdd;
            r.start0[j].w = forward_.sens.start[j].w;
            r.start0[j].ydot = forward_.sens.start[j].ydot;
        }
    if (r.pending_kind == AdjointRecord::Unsupported && r.unsupported_at < 0)
        r.unsupported_at = r.steps;
    if (r.interval > 0 && k % r.interval == 0 && k < r.capacity)
        run_.get_state(r.checkpoint(k / r.interval));
}

// The sweep's state and scratch: the adjoint variables of the state derivative (q, v, qdd,
// lambda, a) of the step being taken back, and the transposed system.
struct Adjoint::Work {
    Vec mq, mv, mqdd, ml, ma;     // adjoint of sigma_{k+1}, then of sigma_k
    Vec cq, cv, cqdd, cl, cp;     // a cost term's gradient
    Vec yq, yl, ye, zq, zl, ze;   // right-hand side and solution of S^T z = y
    Vec rr, rl, rv, qp, vp, tmp;  // adjoints of the linearized residual and the predictor
    Vec qpt, mqt;                 // qp and mq through the transposed tangent operator
    Vec eta;
    Vec my, mydot, mw, ry, yp;  // first-order states (r): adjoints of y, y', w; r^y, y_p
    std::vector<double> dJ;
    State x;  // a recorded state
    // S, sparse on the sparse path (its pattern ordered once per sweep: the entries come from
    // the user's fixed patterns), else dense
#ifdef GALPHA_HAVE_KLU
    std::unique_ptr<KluSystem> klu;
    std::vector<int> slots;  // of the assembled entries, in order
    Eigen::VectorXd rhs;
#endif
    Mat D, Md, Jd, Kd, Cd, Bd, Zd, J0;
    Vec xi;  // a group space's increment of the step (log(q_n^-1 q_{n+1}) block by block)
    Vec bt_eta;  // and B^T eta there
    Eigen::PartialPivLU<Mat> dense_lu;
    std::vector<Eigen::Triplet<double>> entries;
    int np = 0;
    void allocate(int nq, int n, int m, int r, int p)  // (n: nv)
    {
        for (Vec *v : {&my, &mydot, &mw, &ry, &yp})
            v->setZero(r);
        for (Vec *v : {&mq, &mv, &mqdd, &ma, &cq, &cv, &cqdd, &yq, &zq, &rr, &qp, &vp, &tmp, &qpt,
                       &mqt, &xi, &bt_eta})
            v->setZero(n);
        for (Vec *v : {&ml, &cl, &yl, &ye, &zl, &ze, &rl, &rv, &eta})
            v->setZero(m);
        cp.setZero(p);
        dJ.assign(p, 0.0);
        x.allocate(nq, n, m);
        x.allocate_first_order(r);
        np = p;
    }
};

namespace {
using Sparse = Eigen::SparseMatrix<double>;

// A user matrix as a sparse one (dense: every entry).
Sparse to_sparse(const ModelMatrix &A)
{
    Sparse S(A.rows(), A.cols());
    std::vector<Eigen::Triplet<double>> t;
    if (A.dense()) {
        const auto D = A.as_dense();
        for (int j = 0; j < A.cols(); ++j)
            for (int i = 0; i < A.rows(); ++i)
                t.emplace_back(i, j, D(i, j));
    } else {
        for (int k = 0; k < A.nnz(); ++k)
            t.emplace_back(A.row_index()[k], A.col_index()[k], A.data()[k]);
    }
    S.setFromTriplets(t.begin(), t.end());
    return S;
}

void add_block(std::vector<Eigen::Triplet<double>> &t, const Sparse &A, double scale, int row0,
               int col0, bool transposed = false)
{
    for (int j = 0; j < A.outerSize(); ++j)
        for (Sparse::InnerIterator it(A, j); it; ++it)
            transposed ? t.emplace_back(row0 + it.col(), col0 + it.row(), scale * it.value())
                       : t.emplace_back(row0 + it.row(), col0 + it.col(), scale * it.value());
}

}  // namespace

// Step k -> k + 1 backwards: w.mq ... w.ma hold the adjoint of sigma_{k+1}; on return they
// hold that of sigma_k (k > 0), or the parameters have received the start's share (k = 0).
ga_status Adjoint::step_back(long k, Work &w)
{
    const AdjointRecord &r = record_;
    const Params &p = k_.params;
    const bool index2 = k_.formulation == GA_INDEX2_STABILIZED;
    const int nq = k_.nq(), n = k_.nv(), m = k_.m();  // (n: the linear algebra's, nv)
    const double *e0 = r.entry(k), *e1 = r.entry(k + 1);
    const double h = e1[1], rho = e1[2];
    const auto kind = static_cast<AdjointRecord::Kind>(e1[3]);
    const NewtonCoefficients c = newton_coefficients(p, h);
    const double bh2 = p.beta * h * h, t1 = e1[0];

    // the converged step and its exact iteration matrix (as factorize_exact builds it)
    State &x = w.x;
    const double *src = e1 + 4;
    x.q = Eigen::Map<const Vec>(src, nq);
    src += nq;
    for (Vec *v : {&x.v, &x.qdd}) {
        *v = Eigen::Map<const Vec>(src, n);
        src += n;
    }
    x.lambda = Eigen::Map<const Vec>(src, m);
    w.eta = Eigen::Map<const Vec>(src + m, m);
    const int R = k_.r();
    x.y = Eigen::Map<const Vec>(src + 2 * m, R);
    x.ydot = Eigen::Map<const Vec>(src + 2 * m + R, R);
    bool K = false, C = false, Z = false;
    ga_status st = k_.exact_tangents(t1, x, K, C, Z);
    if (!st && R > 0) {  // the coupling blocks at the recorded state (f_ and g there)
        st = k_.coupling_at(t1, x);
    }
    const Vec q_n = Eigen::Map<const Vec>(e0 + 4, nq);
    const ConfigurationSpace &space = k_.model.space;
    if (!st && index2 && m > 0)
        st = k_.evaluate_B(e0[0], q_n);
    if (st)
        return st;

    // S, scaled: rows (beta h^2, 1[, beta h / gamma]), unknowns (d or w, beta h^2 dlambda[, e])
    const int N = n + (index2 ? 2 * m : m);
    const double s3 = p.beta * h / p.gamma;
    // First-order states: dy as unknown beside them (rows of r^y = y' - g, scale 1), the
    // f_y column in the rows of r^q; y-rows -g_q dq - gamma' g_v dw + (c1 I - g_y) dy with
    // dq = w - B^T e, dw = w in index 2 (first_order.cpp eliminates it; here it is assembled).
    const FirstOrderParams &p1 = k_.params1;
    const double c1 = R > 0 ? first_order_newton_coefficient(p1, h) : 0.0;
    // On a group q_{n+1} moves by T(xi) times the increment (sec. 14): K_t, the constraint
    // rows, Z and g_q take it as a right factor, Phi_q^T does not.
    const bool group = !space.euclidean();
    if (group)
        space.increment_between(q_n, x.q, w.xi);
    Mat Fy, Gw, Ge, Gy;
    if (R > 0) {
        const CouplingBlocks &b = k_.coupling();
        Mat gq = b.g_q;
        if (group)
            space.right_multiply_tangent(w.xi, gq.data(), R, R);
        Fy = -bh2 * b.f_y;
        Gw = -(gq + c.gamma_prime * b.g_v);
        Gy = c1 * Mat::Identity(R, R) - b.g_y;
        if (index2 && m > 0) {
            k_.B_matrix().to_dense(w.Bd);
            Ge = gq * w.Bd.transpose();
        }
    }
    const auto add_dense = [&](const Mat &X, int row0, int col0) {
        for (int j = 0; j < X.cols(); ++j)
            for (int i = 0; i < X.rows(); ++i)
                w.entries.emplace_back(row0 + i, col0 + j, X(i, j));
    };
    count(k_.counters, GA_COUNT_FACTORIZATIONS);
    bool singular = false;
    if (k_.sparse()) {
        const Sparse Ms = to_sparse(k_.mass_matrix()), Js = to_sparse(k_.jacobian_matrix());
        Sparse A = (bh2 * c.beta_prime) * Ms;
        if (K)
            A += bh2 * to_sparse(k_.stiffness_matrix());
        if (C)
            A += (bh2 * c.gamma_prime) * to_sparse(k_.damping_matrix());
        w.entries.clear();
        add_block(w.entries, A, 1.0, 0, 0);
        add_block(w.entries, Js, 1.0, 0, n, true);
        add_block(w.entries, Js, 1.0, n, 0);
        if (index2 && m > 0) {
            const Sparse Zs = to_sparse(k_.Z_matrix());
            const Sparse BT = to_sparse(k_.B_matrix()).transpose();
            if (K)
                add_block(w.entries, Sparse(to_sparse(k_.stiffness_matrix()) * BT), -bh2, 0, n + m);
            add_block(w.entries, Sparse(Js * BT), -1.0, n, n + m);
            add_block(w.entries, Zs, s3, n + m, 0);
            add_block(w.entries, Js, 1.0, n + m, 0);
            add_block(w.entries, Sparse(Zs * BT), -s3, n + m, n + m);
        }
        if (R > 0) {
            add_dense(Fy, 0, N);
            add_dense(Gw, N, 0);
            if (index2 && m > 0)
                add_dense(Ge, N, n + m);
            add_dense(Gy, N, N);
        }
#ifdef GALPHA_HAVE_KLU
        if (!w.klu) {
            std::vector<std::pair<int, int>> pattern;
            pattern.reserve(w.entries.size());
            for (const auto &t : w.entries)
                pattern.emplace_back(t.row(), t.col());
            w.klu = std::make_unique<KluSystem>();
            w.klu->setup(N + R, pattern);
            w.slots.resize(w.entries.size());
            for (std::size_t k = 0; k < w.entries.size(); ++k)
                w.slots[k] = w.klu->slot(w.entries[k].row(), w.entries[k].col());
        }
        if (w.slots.size() != w.entries.size())
            return k_.diag.fail(GA_ERR_INTERNAL, "the adjoint's sparse pattern changed");
        std::vector<double> &values = w.klu->values();
        std::fill(values.begin(), values.end(), 0.0);
        for (std::size_t k = 0; k < w.entries.size(); ++k)
            values[w.slots[k]] += w.entries[k].value();
        singular = !w.klu->factorize();
#else
        return diag.fail(GA_ERR_INTERNAL, "sparse path without KLU");
#endif
    } else {
        Mat &D = w.D;
        D.setZero(N + R, N + R);
        k_.mass_matrix().to_dense(w.Md);
        k_.jacobian_matrix().to_dense(w.Jd);
        D.topLeftCorner(n, n) = (bh2 * c.beta_prime) * w.Md;
        if (K) {
            k_.stiffness_matrix().to_dense(w.Kd);
            if (group)
                space.right_multiply_tangent(w.xi, w.Kd.data(), n, n);
            D.topLeftCorner(n, n) += bh2 * w.Kd;
        }
        if (C) {
            k_.damping_matrix().to_dense(w.Cd);
            D.topLeftCorner(n, n) += (bh2 * c.gamma_prime) * w.Cd;
        }
        D.block(0, n, n, m) = w.Jd.transpose();
        if (group && m > 0)
            space.right_multiply_tangent(w.xi, w.Jd.data(), m, m);
        D.block(n, 0, m, n) = w.Jd;
        if (index2 && m > 0) {
            k_.B_matrix().to_dense(w.Bd);
            k_.Z_matrix().to_dense(w.Zd);
            if (group && !k_.Z_matrix().dense()) {
                // a pattern's Z is the difference alone: its bracket Phi_q [., v] added here,
                // with Phi_q before T (the block above, transposed), as the step adds it
                w.J0 = D.block(0, n, n, m).transpose();
                space.add_bracket(x.v, w.J0.data(), m, w.Zd.data());
            }
            if (group)
                space.right_multiply_tangent(w.xi, w.Zd.data(), m, m);
            if (K)
                D.block(0, n + m, n, m) = -bh2 * (w.Kd * w.Bd.transpose());
            D.block(n, n + m, m, m) = -(w.Jd * w.Bd.transpose());
            // (on a group Phi_q without T: the transpose of the block above, since Phi_q's own
            // values may be a pattern's, not a dense matrix)
            if (group)
                D.block(n + m, 0, m, n) = s3 * w.Zd + D.block(0, n, n, m).transpose();
            else
                D.block(n + m, 0, m, n) = s3 * w.Zd + w.Jd;
            D.block(n + m, n + m, m, m) = -s3 * (w.Zd * w.Bd.transpose());
        }
        if (R > 0) {
            D.block(0, N, n, R) = Fy;
            D.block(N, 0, R, n) = Gw;
            if (index2 && m > 0)
                D.block(N, n + m, R, m) = Ge;
            D.block(N, N, R, R) = Gy;
        }
        w.dense_lu.compute(D);
        singular = !(w.dense_lu.rcond() > std::numeric_limits<double>::epsilon());
    }
    if (singular)
        return k_.diag.fail(GA_ERR_SINGULAR,
                            "iteration matrix of the step from t = %.17g (h = %g) is singular in "
                            "the adjoint sweep",
                            e0[0], h);

    // U^T: s_q' = q_p + d, s_v' = v_p + gamma' w, s_qdd' = beta' w, s_lambda' = dlambda,
    // s_a' = (alpha_f sqdd - alpha_m sa + (1 - alpha_f) s_qdd') / (1 - alpha_m)
    const double am = p.alpha_m, af = p.alpha_f;
    const Vec mqdd_total = w.mqdd + ((1.0 - af) / (1.0 - am)) * w.ma;
    w.tmp = c.gamma_prime * w.mv + c.beta_prime * mqdd_total;  // adjoint of w (or of d)
    Eigen::VectorXd y(N + R);
    // s_y' = y_p + dy, s_y'' = c1 dy, s_w' = w_p + (1 - alpha_f1) / (1 - alpha_m1) s_y''
    const double am1 = p1.alpha_m, af1 = p1.alpha_f;
    if (R > 0)
        y.tail(R) = w.my + c1 * (w.mydot + ((1.0 - af1) / (1.0 - am1)) * w.mw);
    // d enters q_{n+1} through the space's tangent operator (an identity in R^n)
    w.mqt = w.mq;
    space.tangent_transpose(q_n, x.q, w.mqt);
    if (index2 && m > 0) {
        y.head(n) = w.tmp + w.mqt;  // d = w - B^T e
        y.segment(n, m) = w.ml / bh2;
        w.ye.setZero();
        k_.B_matrix().multiply_add(-1.0, w.mqt, w.ye);  // (q moves by T d, d = w - B^T e)
        y.segment(n + m, m) = w.ye;
    } else {
        y.head(n) = w.tmp + w.mqt;
        y.segment(n, m) = w.ml / bh2;
    }
    // S^{-T}; the right-hand side was -(rows' scales) (r, r_lambda, r_v)
    Eigen::VectorXd z;
#ifdef GALPHA_HAVE_KLU
    if (k_.sparse()) {
        z = y;
        w.klu->solve_transpose(z.data());
    } else
#endif
    {
        z = w.dense_lu.transpose().solve(y);
    }
    w.rr = -bh2 * z.head(n);
    w.rl = -z.segment(n, m);
    if (index2 && m > 0)
        w.rv = -(p.beta * h / p.gamma) * z.segment(n + m, m);
    if (R > 0)
        w.ry = -z.tail(R);
    // the linearized residual r = K q_p + C v_p + R_p, r_lambda = J q_p, r_v = Z q_p + J v_p
    w.qp = w.mq;
    w.vp = w.mv;
    if (K)
        k_.stiffness_matrix().multiply_transpose_add(1.0, w.rr, w.qp);
    if (C)
        k_.damping_matrix().multiply_transpose_add(1.0, w.rr, w.vp);
    k_.jacobian_matrix().multiply_transpose_add(1.0, w.rl, w.qp);
    if (index2 && m > 0) {
        k_.Z_matrix().multiply_transpose_add(1.0, w.rv, w.qp);
        if (group && !k_.Z_matrix().dense()) {  // and the bracket's transpose (as above)
            w.tmp.setZero();
            k_.jacobian_matrix().multiply_transpose_add(1.0, w.rv, w.tmp);
            space.bracket_transpose_add(x.v, w.tmp, w.qp);
        }
        k_.jacobian_matrix().multiply_transpose_add(1.0, w.rv, w.vp);
    }
    if (R > 0) {  // r^q sees y_p through -f_y; r^y = y'_p - g_q q_p - g_v v_p - g_y y_p
        const CouplingBlocks &b = k_.coupling();
        w.qp.noalias() -= b.g_q.transpose() * w.ry;
        w.vp.noalias() -= b.g_v.transpose() * w.ry;
        w.yp = w.my;
        w.yp.noalias() -= b.f_y.transpose() * w.rr;
        w.yp.noalias() -= b.g_y.transpose() * w.ry;
    }
    // q_p's increment part and the index-2 correction reach it through T, s_q by transport
    w.qpt = w.qp;
    space.tangent_transpose(q_n, x.q, w.qpt);
    for (int j = 0; j < w.np; ++j) {
        Sensitivities &z = forward_.sens;
        if ((st = forward_.constraint_parameter_terms(j, t1, x, index2, index2, e0[0], q_n, w.eta)))
            return st;
        z.rq = z.cq;
        if ((st = forward_.parameter_residual(j, t1, x)))
            return st;
        w.dJ[j] += w.rr.dot(z.rq) + w.rl.dot(z.cl) + w.qpt.dot(z.cbt);
        if (index2 && m > 0)
            w.dJ[j] += w.rv.dot(z.cv);
        if (R > 0) {
            z.ry.setZero();
            if ((st = forward_.rate_parameter_residual(j, t1, x)))
                return st;
            w.dJ[j] += w.ry.dot(z.ry);
        }
    }
    // P^T of the first-order states: w_p = (af1 y'_n - am1 w_n) / (1 - am1),
    // y_p = y_n + h ((1 - gamma1) w_n + gamma1 w_p)
    Vec msy, msydot, msw;
    if (R > 0) {
        const Vec mwp = w.mw + (h * p1.gamma) * w.yp;
        msy = w.yp;
        msw = (h * (1.0 - p1.gamma)) * w.yp - (am1 / (1.0 - am1)) * mwp;
        msydot = (af1 / (1.0 - am1)) * mwp;
    }
    // P^T: a_p = (af sqdd - am sa) / (1 - am), q_p = s_q + h sv + h^2 ((1/2 - beta) sa + beta a_p)
    // (- in index 2 the derivative of B^T eta_bar along s_q), v_p = sv + h ((1 - gamma) sa +
    // gamma a_p)
    const Vec map = (h * h * p.beta) * w.qpt + (h * p.gamma) * w.vp;
    const Vec msv = h * w.qpt + w.vp;
    const Vec msa = (h * h * (0.5 - p.beta)) * w.qpt + (h * (1.0 - p.gamma)) * w.vp -
                    (am / (1.0 - am)) * (map + w.ma);
    const Vec msqdd = (af / (1.0 - am)) * (map + w.ma);
    Vec msq = w.qp;
    space.transport_transpose(q_n, x.q, msq);
    if (index2 && m > 0) {
        if ((st = forward_.correction_derivative(e0[0], q_n, w.eta, w.qpt, w.tmp)))
            return st;
        // That is the derivative of B^T eta along qpt; the adjoint wants its transpose, which
        // is the same only where second derivatives commute (sec. 14): on a group it differs
        // by qpt x (B^T eta) on each rotation.
        if (!space.euclidean()) {
            w.bt_eta.setZero();
            k_.B_matrix().multiply_transpose_add(1.0, w.eta, w.bt_eta);
            space.add_cross(-1.0, w.qpt, w.bt_eta, w.tmp);
        }
        msq += w.tmp;
    }
    if (kind == AdjointRecord::First) {  // the start, differenced in p (sensitivity.cpp)
        for (int j = 0; j < w.np; ++j) {
            w.dJ[j] += msq.dot(r.sigma0[j].q) + msv.dot(r.start0[j].v) + msa.dot(r.start0[j].a) +
                       msqdd.dot(r.start0[j].qdd);
            if (R > 0)
                w.dJ[j] +=
                    msy.dot(r.sigma0[j].y) + msydot.dot(r.start0[j].ydot) + msw.dot(r.start0[j].w);
        }
        return GA_OK;
    }
    // the start as the accepted state (a_n rescaled by rho): the adjoint of sigma_k
    w.mq = msq;
    w.mv = msv;
    w.mqdd = msqdd + (1.0 - rho) * msa;
    w.ma = rho * msa;
    w.ml.setZero();
    if (R > 0) {  // w_n rescaled as a_n (first_order_start)
        w.my = msy;
        w.mydot = msydot + (1.0 - rho) * msw;
        w.mw = rho * msw;
    }
    return GA_OK;
}

// Checkpointing: segment s (steps s K + 1 ... s K + K, or to the last) computed again from
// the checkpoint after step s K into the record's entries, as commit would have written them.
// The steps are attempted as they were (h, Newton tolerance, Taylor steps allowed) and, with
// forward sensitivities, followed by theirs, whose matrix the next step's Newton uses.
ga_status Adjoint::replay_segment(long s)
{
    AdjointRecord &r = record_;
    const long first = s * r.interval, last = std::min(first + r.interval, r.steps);
    if (auto st = run_.set_state(r.checkpoint(s), r.checkpoint_size, true))
        return st;
    r.base = first;
    double *e = r.entry(first);
    e[0] = k_.state().t;
    e += 4;
    for (const Vec *v : {&k_.state().q, &k_.state().v, &k_.state().qdd, &k_.state().lambda})
        put(*v, e);
    e += k_.m();
    put(k_.state().y, e);
    put(k_.state().ydot, e);
    for (long k = first + 1; k <= last; ++k) {
        const double *l = r.log_entry(k);
        const double h = l[1];
        k_.restore_reuse(l + 6);  // the matrix the attempt began with, and its reuse state
        // the kernel and the forward sensitivities' linear step, not the doors after it: a
        // replay records nothing (its entries are written below); adaptive or not as recorded
        // (a fresh start: its first-order states' start)
        ga_status st = k_.attempt_step(h, l[4], std::fmod(l[5], 2.0) != 0.0, l[5] >= 2.0);
        if (!st)
            st = forward_.step(h);
        if (st) {
            k_.diag.append(" (recomputing step %ld from its checkpoint for the adjoint sweep)", k);
            return st;
        }
        if (forward_.sens.forward)
            forward_.sens.accepted.swap(forward_.sens.trial);
        k_.accept_replayed(l[0]);
        double *x = r.entry(k);
        std::copy_n(l, 4, x);
        x += 4;
        for (const Vec *v :
             {&k_.state().q, &k_.state().v, &k_.state().qdd, &k_.state().lambda})
            put(*v, x);
        if (k_.formulation == GA_INDEX2_STABILIZED)
            Eigen::Map<Vec>(x, k_.m()) = k_.eta_bar();
        else
            Eigen::Map<Vec>(x, k_.m()).setZero();
        x += k_.m();
        put(k_.state().y, x);
        put(k_.state().ydot, x);
    }
    return GA_OK;
}

ga_status Adjoint::gradient(ga_cost_fn running, ga_cost_fn terminal, double *J, double *dJ)
{
    if (record_.interval == 0) {
        const ga_status st = sweep(running, terminal, J, dJ);
        k_.forces_see_accepted();  // (the sweep pointed the forces at recorded states)
        return st;
    }
    // The sweep recomputes segments in place: the run is restored afterwards as it was --
    // its state and kept matrix from a checkpoint of it, the rest as saved here.
    AdjointRecord &r = record_;
    std::vector<double> here(run_.state_size());
    run_.get_state(here.data());
    const Stepper::RunPoint point = k_.run_point();
    const EventSet events = run_.events();
    const long base = r.base;
    const std::vector<double> segment = r.data;
    // The segments are computed in matrices of their own, the run's kept one set aside: it
    // comes back as it was, without callbacks (one failing while it was rebuilt made the run
    // go on with a fresh matrix, at Newton's tolerance from the run without the call).
    KeptMatrix kept;
    k_.set_aside_matrix(kept);
    const auto restore = [&] {
        k_.take_back_matrix(kept);
        const ga_status back = run_.set_state(here.data(), here.size(), true, true);
        k_.restore_run_point(point);
        run_.events() = events;
        r.data = segment;
        r.base = base;
        return back;
    };
    ga_status st = GA_OK;
    try {
        st = sweep(running, terminal, J, dJ);
    } catch (...) {  // out of memory in a recomputed segment: the run is restored all the same
        restore();
        throw;
    }
    char message[Diagnostics::kSize];
    k_.diag.copy_to(message);
    const ga_status back = restore();
    if (st) {
        k_.diag.restore(message);
        return st;
    }
    if (back)  // (its own checkpoint, no callback: not expected)
        k_.diag.append(" (restoring the run after the adjoint sweep)");
    return back;
}

ga_status Adjoint::sweep(ga_cost_fn running, ga_cost_fn terminal, double *J, double *dJ)
{
    AdjointRecord &r = record_;
    if (r.unsupported_at >= 0)
        return k_.diag.fail(GA_ERR_STATE,
                            "the recorded run has a step the adjoint sweep does not cover (step "
                            "%ld: a Taylor step, or a fresh start after short steps)",
                            r.unsupported_at);
    if (k_.redundancy == GA_REDUNDANT_DROP && k_.m() > 0)
        return k_.diag.fail(GA_ERR_STATE, "the adjoint sweep with dropped redundant constraints is "
                                          "not built");
    Work w;
    w.allocate(k_.nq(), k_.nv(), k_.m(), k_.r(), forward_.sens.np);
    const long N = r.steps;
    // Cost terms at a recorded state k: its value into `value`, weight times its gradient
    // into the adjoint variables (and into dJ/dp).
    const auto cost = [&](ga_cost_fn fn, long k, double weight, double &total) {
        const double *e = r.entry(k);
        const double *q = e + 4, *v = q + k_.nq(), *qdd = v + k_.nv(), *lambda = qdd + k_.nv();
        double value = 0.0;
        if (auto st =
                k_.model.cost(fn, e[0], q, v, qdd, lambda, value, w.cq, w.cv, w.cqdd, w.cl, w.cp))
            return st;
        total += weight * value;
        w.mq += weight * w.cq;
        w.mv += weight * w.cv;
        w.mqdd += weight * w.cqdd;
        w.ml += weight * w.cl;
        for (int j = 0; j < w.np; ++j)
            w.dJ[j] += weight * w.cp[j];
        return GA_OK;
    };
    // trapezoidal weights of the recorded steps (their sizes from the log with checkpoints)
    const auto size = [&](long k) { return r.interval > 0 ? r.log_entry(k)[1] : r.entry(k)[1]; };
    const auto weight = [&](long k) {
        const double before = k > 0 ? size(k) : 0.0;
        const double after = k < N ? size(k + 1) : 0.0;
        return 0.5 * (before + after);
    };
    double total = 0.0;
    // at x_N
    if (terminal)
        if (auto st = cost(terminal, N, 1.0, total))
            return st;
    for (long k = N; k >= 0; --k) {
        if (running)
            if (auto st = cost(running, k, weight(k), total))
                return st;
        if (k - 1 < r.base && k > 0)  // (checkpointing) the segment that ends at step k
            if (auto st = replay_segment((k - 1) / r.interval))
                return st;
        if (k == 0) {  // x_0 itself: sigma_0 (the start without a step, or L at t0)
            for (int j = 0; j < w.np; ++j) {
                const StateDerivative &s0 = r.sigma0[j];
                w.dJ[j] += w.mq.dot(s0.q) + w.mv.dot(s0.v) + w.mqdd.dot(s0.qdd) +
                           w.ml.dot(s0.lambda) + w.ma.dot(s0.a) + w.my.dot(s0.y) +
                           w.mydot.dot(s0.ydot) + w.mw.dot(s0.w);
            }
            break;
        }
        if (auto st = step_back(k - 1, w)) {
            k_.diag.append(" (adjoint sweep, step %ld of %ld)", k, N);
            return st;
        }
        if (k - 1 == 0) {  // the first step took the start's share (sigma_0 included)
            w.mq.setZero();
            w.mv.setZero();
            w.mqdd.setZero();
            w.ml.setZero();
            w.ma.setZero();
            w.my.setZero();
            w.mydot.setZero();
            w.mw.setZero();
        }
    }
    // A run near the range of double (a free particle in adaptive steps of 1e153, exact for
    // it) overflows the sweep's products: no such gradient with GA_OK.
    int bad = -1;
    for (int j = 0; j < w.np && bad < 0; ++j)
        if (!std::isfinite(w.dJ[j]))
            bad = j;
    if (!std::isfinite(total) || bad >= 0)
        return k_.diag.fail(GA_ERR_NONFINITE,
                            "the adjoint sweep overflowed: J = %g, dJ/dp_%d = %g (the recorded "
                            "run's values or step sizes near the range of double)",
                            total, bad < 0 ? 0 : bad, w.dJ[bad < 0 ? 0 : bad]);
    *J = total;
    for (int j = 0; j < w.np; ++j)
        dJ[j] = w.dJ[j];
    return GA_OK;
}

}  // namespace ga
