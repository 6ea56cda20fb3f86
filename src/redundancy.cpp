#include "redundancy.hpp"

#include <cmath>
#include <new>

#ifdef GALPHA_HAVE_SPQR
#include <SuiteSparseQR_C.h>
#endif

namespace ga {

namespace {
constexpr double kDependence = 1e-10;     // remainder / norm of a dependent gradient
constexpr double kMaxDenseEntries = 4e6;  // n m for the dense Gram-Schmidt

// Gram-Schmidt in index order on the columns of Phi_q^T, each projected twice against the
// kept ones (for orthogonality in floating point).
int dense_in_order(const ModelMatrix &J, int n, int m, unsigned char *active)
{
    Mat Jt = Mat::Zero(n, m);
    if (J.dense())
        Jt = J.as_dense().transpose();
    else
        for (int k = 0; k < J.nnz(); ++k)
            Jt(J.col_index()[k], J.row_index()[k]) += J.data()[k];
    Mat basis(n, m);
    int kept = 0;
    for (int i = 0; i < m; ++i) {
        Vec r = Jt.col(i);
        const double norm = r.norm();
        for (int pass = 0; pass < 2; ++pass)
            for (int k = 0; k < kept; ++k)
                r -= basis.col(k).dot(r) * basis.col(k);
        const double rest = r.norm();
        active[i] = norm > 0.0 && rest > kDependence * norm;
        if (active[i])
            basis.col(kept++) = r / rest;
    }
    return kept;
}

#ifdef GALPHA_HAVE_SPQR
// Sparse QR of Phi_q^T with its columns (the constraints) normalized and in their given order
// (SPQR_ORDERING_FIXED): a column whose remainder falls below the tolerance is "dead" and
// gets no pivot row in the squeezed R, whose live columns have their last entry in the row
// that counts the live columns before them.
int sparse_in_order(const ModelMatrix &J, int n, int m, unsigned char *active)
{
    cholmod_common cc;
    cholmod_l_start(&cc);
    cc.print = 0;  // CHOLMOD prints its errors to stdout unless told not to; galpha never prints
    std::vector<double> norm2(m, 0.0);
    for (int k = 0; k < J.nnz(); ++k)
        norm2[J.row_index()[k]] += J.data()[k] * J.data()[k];  // (duplicates: close enough)
    cholmod_triplet *T =
        cholmod_l_allocate_triplet(n, m, J.nnz() > 0 ? J.nnz() : 1, 0, CHOLMOD_REAL, &cc);
    cholmod_sparse *A = nullptr, *R = nullptr;
    SuiteSparse_long *E = nullptr;
    int rank = -1;
    if (T) {
        auto *ti = static_cast<SuiteSparse_long *>(T->i);
        auto *tj = static_cast<SuiteSparse_long *>(T->j);
        auto *tx = static_cast<double *>(T->x);
        for (int k = 0; k < J.nnz(); ++k) {
            const int row = J.row_index()[k];
            ti[k] = J.col_index()[k];
            tj[k] = row;
            tx[k] = norm2[row] > 0.0 ? J.data()[k] / std::sqrt(norm2[row]) : 0.0;
        }
        T->nnz = J.nnz();
        A = cholmod_l_triplet_to_sparse(T, J.nnz(), &cc);
    }
    if (A && SuiteSparseQR_C(SPQR_ORDERING_FIXED, kDependence, 0, 0, A, nullptr, nullptr,
                             nullptr, nullptr, &R, &E, nullptr, nullptr, nullptr, &cc) >= 0 &&
        R && !E) {
        const auto *Rp = static_cast<const SuiteSparse_long *>(R->p);
        const auto *Ri = static_cast<const SuiteSparse_long *>(R->i);
        const auto *Rx = static_cast<const double *>(R->x);
        SuiteSparse_long live = 0;
        for (int j = 0; j < m; ++j) {
            bool pivot = false;
            for (SuiteSparse_long p = Rp[j]; p < Rp[j + 1]; ++p)
                pivot = pivot || (Ri[p] == live && Rx[p] != 0.0);
            active[j] = pivot && norm2[j] > 0.0;
            live += active[j];
        }
        rank = static_cast<int>(live);
    }
    const bool out_of_memory = cc.status == CHOLMOD_OUT_OF_MEMORY;
    cholmod_l_free_sparse(&R, &cc);
    cholmod_l_free_sparse(&A, &cc);
    cholmod_l_free_triplet(&T, &cc);
    if (E)
        cholmod_l_free(m, sizeof(SuiteSparse_long), E, &cc);
    cholmod_l_finish(&cc);
    if (out_of_memory)
        throw std::bad_alloc();
    return rank;
}
#endif
}  // namespace

int independent_in_order(const ModelMatrix &J, int n, int m, unsigned char *active)
{
#ifdef GALPHA_HAVE_SPQR
    if (!J.dense())
        return sparse_in_order(J, n, m, active);
#endif
    if (static_cast<double>(n) * m > kMaxDenseEntries)
        return -1;
    return dense_in_order(J, n, m, active);
}

}  // namespace ga
