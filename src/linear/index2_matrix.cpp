#include "index2_matrix.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <limits>
#include <new>
#include <utility>
#include <vector>

#include "assemble.hpp"
#include "klu_system.hpp"
#include "condition.hpp"
#include "unblocked_lu.hpp"

namespace ga {

namespace {

// cM of the scaled system: (1 - alpha_m) / (1 - alpha_f), the factor of M in A
double mass_factor(const Params &p) { return (1.0 - p.alpha_m) / (1.0 - p.alpha_f); }
}  // namespace

struct Index2Matrix::Dense {
    int n = 0, m = 0;
    DenseKind kind = DenseKind::Auto;
    bool unblocked = true;  // the last factorization is the unblocked kernel's (in S)
    Mat S, A, Bd;
    Eigen::PartialPivLU<Mat> lu;
    Eigen::VectorXi ipiv, extent;
    Vec rhs, x, inverse_diagonal;
    double pivot_ratio = 0.0;
    // condition estimate on demand (condition.hpp on the factors, LAPACK layout from either LU): the
    // 1-norm of S is taken before the unblocked kernel overwrites it
    double anorm = 0.0;
    mutable double rcond = 0.0;
    mutable bool rcond_valid = false;
    mutable Vec work;
};

#ifdef GALPHA_HAVE_KLU
struct Index2Matrix::Sparse {
    int n = 0, m = 0;
    bool reduced = true;  // the (n + 2m) system of the dense path; else the augmented one
    KluSystem S;
    // slots of each block's entries, in the order of the block's pattern (J3: the third block
    // row's Phi_q, which Z shares; augmented only: M and C at w, BT, minus_I, plus_I)
    std::vector<int> K, M, C, JT, J2, J3, Z, BT, minus_I, plus_I;
    // reduced only: the products A B^T and Phi_q B^T, one term per entry: S[slot] += c *
    // left[left_k] * B[b_k] (left: M or C for A B^T, J for Phi_q B^T)
    struct Term {
        int slot, left_k, b_k;
    };
    std::vector<Term> MBt, CBt, JBt;
    // inactive constraints: the rows of J's entries and of J2's and Z's (J_low's layout)
    std::vector<int> J_rows, low_rows, lambda_diag, eta_diag;
    Vec rhs;
};
#else
struct Index2Matrix::Sparse {};
#endif

Index2Matrix::Index2Matrix() = default;
Index2Matrix::~Index2Matrix() = default;
Index2Matrix::Index2Matrix(Index2Matrix &&) noexcept = default;
Index2Matrix &Index2Matrix::operator=(Index2Matrix &&) noexcept = default;

void Index2Matrix::reset()
{
    dense_.reset();
    sparse_.reset();
    active_ = nullptr;
}

void Index2Matrix::setup(int n, int m, bool sparse, DenseKind dense_kind, const ModelMatrix &M,
                         const ModelMatrix &J, const ModelMatrix &K, const ModelMatrix &C,
                         const ModelMatrix *J_low, const unsigned char *active, bool amd_first)
{
    active_ = active;
#ifdef GALPHA_HAVE_KLU
    if (sparse) {
        sparse_ = setup_sparse(n, m, M, J, K, C, J_low ? *J_low : J, active != nullptr,
                               amd_first);
        return;
    }
#else
    (void)sparse, (void)M, (void)J, (void)K, (void)C, (void)amd_first;
#endif
    (void)J_low;  // dense: the lower block is written over J's at each factorization
    auto d = std::make_unique<Dense>();
    d->n = n;
    d->m = m;
    const int N = n + 2 * m;
    d->S.setZero(N, N);
    d->A.setZero(n, n);
    d->Bd.setZero(m, n);
    // Eigen's LU unless galpha's unblocked kernel is asked for or preferred (LAPACK's is not
    // offered for this system)
    d->kind = dense_kind;
    d->unblocked = dense_kind == DenseKind::Unblocked ||
                   (dense_kind == DenseKind::Auto && unblocked_lu_preferred(N, d->S.data()));
    if (dense_kind != DenseKind::Unblocked)
        d->lu = Eigen::PartialPivLU<Mat>(N);
    d->ipiv.setZero(N);
    d->extent.setZero(2 * N);
    d->inverse_diagonal.setZero(N);
    d->rhs.setZero(N);
    d->x.setZero(N);
    d->work.setZero(2 * static_cast<Eigen::Index>(N));
    dense_ = std::move(d);
}

#ifdef GALPHA_HAVE_KLU
// The sparse system. Reduced: the matrix of the dense path (index2_matrix.hpp, first display),
// unknowns d [0, n), lambda_bar [n, n + m), eta_bar [n + m, n + 2m), with the products A B^T
// and Phi_q B^T assembled term by term on patterns fixed here. Augmented (second display, the
// Newmark increment w an unknown of its own): only where the products would hold many more
// entries than the augmented matrix -- a coordinate in many constraints makes Phi_q B^T dense
// in them. On the chain the reduced system has 7N unknowns instead of 10N, fills 0.63 times
// as much, and refactorizes and solves 1.5 to 2 times faster.
std::unique_ptr<Index2Matrix::Sparse> Index2Matrix::setup_sparse(int n, int m,
                                                                 const ModelMatrix &M,
                                                                 const ModelMatrix &J,
                                                                 const ModelMatrix &K,
                                                                 const ModelMatrix &C,
                                                                 const ModelMatrix &L,
                                                                 bool with_inactive,
                                                                 bool amd_first)
{
    auto s = std::make_unique<Sparse>();
    const auto start = amd_first ? KluSystem::Ordering::Amd : KluSystem::Ordering::Auto;
    s->n = n;
    s->m = m;
    const std::vector<int> &Jr = J.row_index(), &Jc = J.col_index();
    std::vector<std::pair<int, int>> entries;
    auto block = [&entries](const ModelMatrix &A, bool transposed, int row0, int col0) {
        for (int k = 0; k < A.nnz(); ++k) {
            const int i = A.row_index()[k], j = A.col_index()[k];
            entries.emplace_back(transposed ? row0 + j : row0 + i,
                                 transposed ? col0 + i : col0 + j);
        }
    };
    auto slots = [&s](const ModelMatrix &A, bool transposed, int row0, int col0) {
        std::vector<int> out(A.nnz());
        for (int k = 0; k < A.nnz(); ++k) {
            const int i = A.row_index()[k], j = A.col_index()[k];
            out[k] = transposed ? s->S.slot(row0 + j, col0 + i) : s->S.slot(row0 + i, col0 + j);
        }
        return out;
    };

    // the reduced pattern, and whether it stays sparse
    std::vector<std::vector<int>> M_col(n), C_col(n), J_col(n);  // entries of each column
    for (int k = 0; k < M.nnz(); ++k)
        M_col[M.col_index()[k]].push_back(k);
    for (int k = 0; k < C.nnz(); ++k)
        C_col[C.col_index()[k]].push_back(k);
    for (int k = 0; k < J.nnz(); ++k)
        J_col[Jc[k]].push_back(k);
    const int l0 = n, e0 = n + m;
    // every product term: (left factor entry, B entry k = (r, j)) -> (row of left, e0 + r)
    auto for_each_term = [&](auto &&term) {
        for (int k = 0; k < J.nnz(); ++k) {
            for (int a : M_col[Jc[k]])
                term(s->MBt, a, k, M.row_index()[a]);
            for (int a : C_col[Jc[k]])
                term(s->CBt, a, k, C.row_index()[a]);
            for (int a : J_col[Jc[k]])
                term(s->JBt, a, k, e0 + Jr[a]);
        }
    };
    // The terms are counted before any is stored: around a hub their number grows like the
    // square of its constraints, and the augmented form needs none.
    const std::size_t augmented_entries = K.nnz() + M.nnz() + C.nnz() + 5 * J.nnz() + 2 * n;
    std::size_t terms = 0;
    for (int j = 0; j < n; ++j)
        terms += J_col[j].size() * (M_col[j].size() + C_col[j].size() + J_col[j].size());
    s->reduced = terms <= 4 * augmented_entries;
    if (s->reduced) {
        for (int i = 0; i < n; ++i)
            entries.emplace_back(i, i);
        block(M, false, 0, 0);
        block(C, false, 0, 0);
        block(K, false, 0, 0);
        block(J, true, 0, l0);   // Phi_q^T
        block(L, false, l0, 0);  // Phi_q (T)
        block(J, false, e0, 0);  // Phi_q + (beta h / gamma) Z (T): Z has the pattern of L
        block(L, false, e0, 0);
        for_each_term([&](std::vector<Sparse::Term> &, int, int k, int row) {
            entries.emplace_back(row, e0 + Jr[k]);
        });
        if (with_inactive)
            for (int i = 0; i < m; ++i) {
                entries.emplace_back(l0 + i, l0 + i);
                entries.emplace_back(e0 + i, e0 + i);
            }
        std::sort(entries.begin(), entries.end());
        entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
        s->reduced = entries.size() <= 2 * augmented_entries;
    }

    if (s->reduced) {
        s->S.setup(n + 2 * m, std::move(entries), start);
        s->M = slots(M, false, 0, 0);
        s->C = slots(C, false, 0, 0);
        s->K = slots(K, false, 0, 0);
        s->JT = slots(J, true, 0, l0);
        s->J2 = slots(L, false, l0, 0);
        s->J3 = slots(J, false, e0, 0);
        for_each_term([&](std::vector<Sparse::Term> &terms, int a, int k, int row) {
            terms.push_back({s->S.slot(row, e0 + Jr[k]), a, k});
        });
    } else {
        // columns: d [0, n), w [n, 2n), lambda_bar [2n, 2n + m), eta_bar [2n + m, 2n + 2m);
        // rows: dynamics [0, n), w - d - B^T eta_bar [n, 2n), Phi [2n, 2n + m),
        // velocity constraint [2n + m, 2n + 2m)
        const int w0 = n;
        entries.clear();
        block(K, false, 0, 0);
        block(M, false, 0, w0);
        block(C, false, 0, w0);
        block(J, true, 0, 2 * n);           // Phi_q^T
        block(J, true, w0, 2 * n + m);      // -B^T (B has the layout of Phi_q)
        block(L, false, 2 * n, 0);          // Phi_q (T) d
        block(J, false, 2 * n + m, w0);     // Phi_q w
        block(L, false, 2 * n + m, 0);      // (beta h / gamma) Z (T) d
        for (int i = 0; i < n; ++i) {
            entries.emplace_back(w0 + i, i);       // -I
            entries.emplace_back(w0 + i, w0 + i);  // I
        }
        if (with_inactive)
            for (int i = 0; i < m; ++i) {
                entries.emplace_back(2 * n + i, 2 * n + i);
                entries.emplace_back(2 * n + m + i, 2 * n + m + i);
            }
        s->S.setup(2 * n + 2 * m, std::move(entries), start);
        s->K = slots(K, false, 0, 0);
        s->M = slots(M, false, 0, w0);
        s->C = slots(C, false, 0, w0);
        s->JT = slots(J, true, 0, 2 * n);
        s->BT = slots(J, true, w0, 2 * n + m);
        s->J2 = slots(L, false, 2 * n, 0);
        s->J3 = slots(J, false, 2 * n + m, w0);
        for (int i = 0; i < n; ++i) {
            s->minus_I.push_back(s->S.slot(w0 + i, i));
            s->plus_I.push_back(s->S.slot(w0 + i, w0 + i));
        }
    }
    // Z: in the first block column of the velocity-constraint rows, J3's slots (reduced) or
    // those of Phi_q d there (augmented)
    s->Z = slots(L, false, s->reduced ? e0 : 2 * n + m, 0);
    if (with_inactive) {
        s->J_rows = Jr;
        s->low_rows = L.row_index();
        const int lambda0 = s->reduced ? l0 : 2 * n, eta0 = s->reduced ? e0 : 2 * n + m;
        for (int i = 0; i < m; ++i) {
            s->lambda_diag.push_back(s->S.slot(lambda0 + i, lambda0 + i));
            s->eta_diag.push_back(s->S.slot(eta0 + i, eta0 + i));
        }
    }
    s->rhs.setZero(s->reduced ? n + 2 * m : 2 * n + 2 * m);
    return s;
}
#endif

bool Index2Matrix::factorize(const ModelMatrix &M, const ModelMatrix *C, const ModelMatrix *K,
                             const ModelMatrix &J, const ModelMatrix &B, const ModelMatrix *Z,
                             const Params &p, double h, const ModelMatrix *J_low)
{
    const double cZ = p.beta * h / p.gamma;
    const double cM = mass_factor(p);
#ifdef GALPHA_HAVE_KLU
    if (sparse_) {
        Sparse &s = *sparse_;
        std::vector<double> &v = s.S.values();
        std::fill(v.begin(), v.end(), 0.0);
        auto scatter = [&](const ModelMatrix &A, const std::vector<int> &slots, double c) {
            const double *a = A.data();
            for (std::size_t k = 0; k < slots.size(); ++k)
                v[slots[k]] += c * a[k];
        };
        auto products = [&](const ModelMatrix &A, const std::vector<Sparse::Term> &terms,
                            double c) {
            const double *a = A.data(), *b = B.data();
            for (const Sparse::Term &t : terms)
                v[t.slot] += c * a[t.left_k] * b[t.b_k];
        };
        scatter(M, s.M, cM);
        if (C)
            scatter(*C, s.C, p.gamma * h);
        if (K)
            scatter(*K, s.K, p.beta * h * h);
        scatter(J, s.JT, 1.0);
        scatter(J_low ? *J_low : J, s.J2, 1.0);
        scatter(J, s.J3, 1.0);
        if (Z)
            scatter(*Z, s.Z, cZ);
        if (s.reduced) {
            products(M, s.MBt, cM);  // A B^T
            if (C)
                products(*C, s.CBt, p.gamma * h);
            products(J, s.JBt, 1.0);  // Phi_q B^T
        } else {
            scatter(B, s.BT, -1.0);
            for (int k : s.minus_I)
                v[k] -= 1.0;
            for (int k : s.plus_I)
                v[k] += 1.0;
        }
        if (active_) {
            // an inactive constraint's rows and columns: those of the identity
            const std::vector<int> &r = s.J_rows, &low = s.low_rows;
            for (std::size_t k = 0; k < r.size(); ++k)
                if (!active_[r[k]]) {
                    v[s.JT[k]] = v[s.J3[k]] = 0.0;
                    if (!s.reduced)
                        v[s.BT[k]] = 0.0;
                }
            for (std::size_t k = 0; k < low.size(); ++k)
                if (!active_[low[k]])
                    v[s.J2[k]] = v[s.Z[k]] = 0.0;
            for (const auto *terms : {&s.MBt, &s.CBt, &s.JBt})
                for (const Sparse::Term &t : *terms)
                    if (!active_[r[t.b_k]] || (terms == &s.JBt && !active_[r[t.left_k]]))
                        v[t.slot] = 0.0;
            for (int i = 0; i < s.m; ++i)
                if (!active_[i])
                    v[s.lambda_diag[i]] = v[s.eta_diag[i]] = 1.0;
        }
        return s.S.factorize();
    }
#endif
    Dense &d = *dense_;
    const int n = d.n, m = d.m;
    d.S.setZero();
    d.A.setZero();
    add_block(d.A.data(), n, 0, 0, cM, M);  // cM M + gamma h C: also the block that multiplies B^T
    if (C)
        add_block(d.A.data(), n, 0, 0, p.gamma * h, *C);
    d.Bd.setZero();
    add_block(d.Bd.data(), m, 0, 0, 1.0, B);
    d.S.block(0, n + m, n, m).noalias() = d.A * d.Bd.transpose();
    d.S.topLeftCorner(n, n) = d.A;
    const int N = n + 2 * m;
    if (K)
        add_block(d.S.data(), N, 0, 0, p.beta * h * h, *K);
    auto Jd = d.S.block(n, 0, m, n);
    add_block(d.S.data(), N, n, 0, 1.0, J);
    d.S.block(0, n, n, m) = Jd.transpose();
    d.S.block(n + m, 0, m, n) = Jd;
    d.S.block(n + m, n + m, m, m).noalias() = Jd * d.Bd.transpose();
    if (J_low) {
        Jd.setZero();
        add_block(d.S.data(), N, n, 0, 1.0, *J_low);
    }
    if (Z)
        add_block(d.S.data(), N, n + m, 0, cZ, *Z);
    if (active_)
        for (int i = 0; i < m; ++i)
            if (!active_[i])
                for (const int k : {n + i, n + m + i}) {
                    d.S.row(k).setZero();
                    d.S.col(k).setZero();
                    d.S(k, k) = 1.0;
                }
    d.unblocked = d.kind == DenseKind::Unblocked ||
                  (d.kind == DenseKind::Auto && unblocked_lu_preferred(N, d.S.data()));
    d.rcond_valid = false;
    if (d.unblocked) {
        d.anorm = d.S.cwiseAbs().colwise().sum().maxCoeff();
        if (!unblocked_lu(N, d.S.data(), d.ipiv.data(), d.extent.data(),
                          d.inverse_diagonal.data())) {
            d.pivot_ratio = 0.0;
            return false;
        }
    } else {
        d.lu.compute(d.S);
    }
    const auto U = (d.unblocked ? d.S : d.lu.matrixLU()).diagonal().cwiseAbs();
    const double umax = U.maxCoeff();
    d.pivot_ratio = umax > 0.0 ? U.minCoeff() / umax : 0.0;
    return d.pivot_ratio >= N * std::numeric_limits<double>::epsilon();
}

void Index2Matrix::solve(const Vec &rq, const Vec &phi, const Vec &phi_v, const Params &p,
                         double h, const ModelMatrix &B, Vec &d, Vec &w, Vec &dlambda,
                         Vec &eta_bar)
{
    const double bh2 = p.beta * h * h;
#ifdef GALPHA_HAVE_KLU
    if (sparse_) {
        Sparse &s = *sparse_;
        const int n = s.n, m = s.m;
        const int nw = s.reduced ? 0 : n;  // the Newmark rows and unknowns (augmented only)
        s.rhs.head(n) = -bh2 * rq;
        s.rhs.segment(n, nw).setZero();
        s.rhs.segment(n + nw, m) = -phi;
        s.rhs.tail(m) = -(p.beta * h / p.gamma) * phi_v;
        if (active_)
            for (int i = 0; i < m; ++i)
                if (!active_[i])
                    s.rhs[n + nw + i] = s.rhs[n + nw + m + i] = 0.0;
        s.S.solve(s.rhs.data());
        d = s.rhs.head(n);
        dlambda = s.rhs.segment(n + nw, m) / bh2;
        eta_bar = s.rhs.tail(m);
        if (s.reduced) {
            w = d;
            if (m > 0)
                B.multiply_transpose_add(1.0, eta_bar, w);
        } else {
            w = s.rhs.segment(n, n);
        }
        return;
    }
#endif
    Dense &x = *dense_;
    const int n = x.n, m = x.m;
    x.rhs.head(n) = -bh2 * rq;
    x.rhs.segment(n, m) = -phi;
    x.rhs.tail(m) = -(p.beta * h / p.gamma) * phi_v;
    if (active_)
        for (int i = 0; i < m; ++i)
            if (!active_[i])
                x.rhs[n + i] = x.rhs[n + m + i] = 0.0;
    if (x.unblocked) {
        x.x = x.rhs;
        unblocked_lu_solve(n + 2 * m, x.S.data(), x.ipiv.data(), x.extent.data(),
                           x.inverse_diagonal.data(), x.x.data());
    } else {
        x.x.noalias() = x.lu.solve(x.rhs);
    }
    d = x.x.head(n);
    dlambda = x.x.segment(n, m) / bh2;
    eta_bar = x.x.tail(m);
    w = d;
    if (m > 0)
        B.multiply_transpose_add(1.0, eta_bar, w);
}

bool Index2Matrix::sparse_reduced() const
{
#ifdef GALPHA_HAVE_KLU
    return sparse_ && sparse_->reduced;
#else
    return false;
#endif
}

double Index2Matrix::rcond() const
{
#ifdef GALPHA_HAVE_KLU
    if (sparse_)
        return sparse_->S.rcond_estimate();
#endif
    if (!dense_ || !(dense_->pivot_ratio > 0.0))
        return 0.0;
    const Dense &d = *dense_;
    if (!d.rcond_valid) {
        const int N = static_cast<int>(d.S.rows());
        const Mat &factors = d.unblocked ? d.S : d.lu.matrixLU();
        // unblocked: S holds the factors, its norm was taken before; Eigen factorized a copy
        const double anorm = d.unblocked ? d.anorm : norm1(N, d.S.data());
        d.rcond = lu_rcond(N, factors.data(), anorm, d.work.data());
        d.rcond_valid = true;
    }
    return d.rcond;
}

void Index2Matrix::forget_pivots()
{
#ifdef GALPHA_HAVE_KLU
    if (sparse_)
        sparse_->S.forget_pivots();
#endif
}

void Index2Matrix::save_pivots(double *out) const
{
#ifdef GALPHA_HAVE_KLU
    if (sparse_)
        sparse_->S.save_pivots(out);
#else
    (void)out;
#endif
}

bool Index2Matrix::pivots_loadable(const double *in) const
{
#ifdef GALPHA_HAVE_KLU
    if (sparse_)
        return sparse_->S.pivots_loadable(in);
#endif
    return pivot_block_header_ok(in);
}

void Index2Matrix::load_pivots(const double *in)
{
#ifdef GALPHA_HAVE_KLU
    if (sparse_)
        sparse_->S.load_pivots(in);
#else
    (void)in;
#endif
}

void Index2Matrix::reserve_factors()
{
#ifdef GALPHA_HAVE_KLU
    if (sparse_)
        sparse_->S.reserve_factors();
#endif
}

const char *Index2Matrix::name() const
{
    if (sparse_)
        return "sparse KLU (stabilized index-2)";
    return dense_ && !dense_->unblocked ? "dense Eigen LU (stabilized index-2)"
                                        : "dense unblocked LU (stabilized index-2)";
}

const char *Index2Matrix::ordering() const
{
#ifdef GALPHA_HAVE_KLU
    if (sparse_)
        return sparse_->S.ordering();
#endif
    return "";
}

}  // namespace ga
