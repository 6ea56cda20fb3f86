// Dense backend: S as an (n+m) x (n+m) column-major matrix, LU with partial pivoting by
// LAPACK (dgetrf/dgetrs), Eigen (PartialPivLU) or galpha's unblocked kernel (unblocked_lu.hpp),
// condition estimate by galpha's own (condition.hpp) on the factors in every case. By default (Auto) each
// factorization takes the unblocked kernel when S is small or mostly zero, Eigen's otherwise;
// bench/linear_algebra measures all of them.
#include <Eigen/LU>
#include <cstddef>
#include <limits>

#include "assemble.hpp"
#include "backend.hpp"
#include "condition.hpp"
#include "lapack.hpp"
#include "unblocked_lu.hpp"


namespace ga {

namespace {

class DenseBackend final : public LinearBackend {
public:
    explicit DenseBackend(DenseKind kind) : kind_(kind) {}

    void setup(int n, int m, const ModelMatrix &, const ModelMatrix &, const ModelMatrix &,
               const ModelMatrix &, bool, const ModelMatrix *) override
    {
        n_ = n;
        m_ = m;
        const int N = n + m;
        S_.setZero(N, N);
        ipiv_.setZero(N);
        extent_.setZero(2 * N);
        inverse_diagonal_.setZero(N);
        work_.setZero(2 * static_cast<Eigen::Index>(N));
        x_.setZero(N);
        if (kind_ == DenseKind::Eigen || kind_ == DenseKind::Auto)
            eigen_lu_ = Eigen::PartialPivLU<Mat>(N);
        // (before the first factorization the name reports the choice for S = 0)
        unblocked_ = kind_ == DenseKind::Unblocked ||
                     (kind_ == DenseKind::Auto && unblocked_lu_preferred(N, S_.data()));
    }

    bool factorize(const SaddleBlocks &b) override
    {
        const int N = n_ + m_;
        double *S = S_.data();
        S_.setZero();
        if (b.M)
            add_block(S, N, 0, 0, b.cM, *b.M);
        else
            S_.topLeftCorner(n_, n_).diagonal().setOnes();
        if (b.C)
            add_block(S, N, 0, 0, b.cC, *b.C);
        if (b.K)
            add_block(S, N, 0, 0, b.cK, *b.K);
        if (m_ > 0) {
            add_block(S, N, n_, 0, 1.0, *b.J);
            if (b.active)
                for (int i = 0; i < m_; ++i)
                    if (!b.active[i]) {
                        S_.row(n_ + i).setZero();
                        S_(n_ + i, n_ + i) = 1.0;
                    }
            for (int j = 0; j < m_; ++j)  // Phi_q^T: column n + j is row n + j of the lower block
                for (int i = 0; i < n_; ++i)
                    S[static_cast<std::ptrdiff_t>(n_ + j) * N + i] =
                        S[static_cast<std::ptrdiff_t>(i) * N + n_ + j];
            if (b.J_low) {  // a lower block of its own (Phi_q T on a group space)
                S_.block(n_, 0, m_, n_).setZero();
                add_block(S, N, n_, 0, 1.0, *b.J_low);
                if (b.active)
                    for (int i = 0; i < m_; ++i)
                        if (!b.active[i])
                            S_.row(n_ + i).head(n_).setZero();
            }
        }
        rcond_valid_ = false;
        unblocked_ = kind_ == DenseKind::Unblocked ||
                     (kind_ == DenseKind::Auto && unblocked_lu_preferred(N, S_.data()));
        // The condition estimate (as expensive as the LU for small sizes) is computed
        // only when asked for; it needs the 1-norm of S, which in-place factors overwrite.
        if (kind_ == DenseKind::Lapack || unblocked_)
            anorm_ = S_.cwiseAbs().colwise().sum().maxCoeff();
        if (kind_ == DenseKind::Lapack) {
            int info = 0;
            dgetrf_(&N, &N, S_.data(), &N, ipiv_.data(), &info);
            if (info > 0) {  // exact zero pivot
                pivot_ratio_ = 0.0;
                return false;
            }
        } else if (unblocked_) {
            if (!unblocked_lu(N, S_.data(), ipiv_.data(), extent_.data(),
                              inverse_diagonal_.data())) {
                pivot_ratio_ = 0.0;
                return false;
            }
        } else {
            eigen_lu_.compute(S_);
        }
        // Singular in double precision when the pivots span more than 1/(N eps).
        const auto U = factors().diagonal().cwiseAbs();
        const double umax = U.maxCoeff();
        pivot_ratio_ = umax > 0.0 ? U.minCoeff() / umax : 0.0;
        return pivot_ratio_ >= N * std::numeric_limits<double>::epsilon();
    }

    double rcond() const override
    {
        if (!rcond_valid_ && pivot_ratio_ > 0.0) {
            const int N = n_ + m_;
            if (in_eigen())  // S is intact: Eigen factorizes a copy
                anorm_ = norm1(N, S_.data());
            rcond_ = lu_rcond(N, factors().data(), anorm_, work_.data());
            rcond_valid_ = true;
        }
        return pivot_ratio_ > 0.0 ? rcond_ : 0.0;
    }

    void solve(Vec &rhs) override
    {
        if (unblocked_) {
            unblocked_lu_solve(n_ + m_, S_.data(), ipiv_.data(), extent_.data(),
                               inverse_diagonal_.data(), rhs.data());
            return;
        }
        if (in_eigen()) {
            x_.noalias() = eigen_lu_.solve(rhs);  // into scratch: in-place permutation allocates
            rhs = x_;
            return;
        }
        const int N = n_ + m_;
        const int nrhs = 1;
        int info = 0;
        dgetrs_("N", &N, &nrhs, S_.data(), &N, ipiv_.data(), rhs.data(), &N, &info, 1);
    }

    const char *name() const override
    {
        if (kind_ == DenseKind::Lapack)
            return "dense LAPACK LU";
        return unblocked_ ? "dense unblocked LU" : "dense Eigen LU";
    }

private:
    DenseKind kind_;
    int n_ = 0, m_ = 0;
    bool in_eigen() const { return kind_ != DenseKind::Lapack && !unblocked_; }
    const Mat &factors() const { return in_eigen() ? eigen_lu_.matrixLU() : S_; }

    Mat S_;
    Eigen::VectorXi ipiv_, extent_;
    mutable Vec work_;
    Vec x_, inverse_diagonal_;
    Eigen::PartialPivLU<Mat> eigen_lu_;
    mutable double anorm_ = 0.0;
    double pivot_ratio_ = 0.0;
    mutable double rcond_ = 0.0;
    mutable bool rcond_valid_ = false;
    bool unblocked_ = false;  // the last factorization is the unblocked kernel's
};

}  // namespace

std::unique_ptr<LinearBackend> make_dense_backend(DenseKind kind)
{
    return std::make_unique<DenseBackend>(kind);
}

}  // namespace ga
