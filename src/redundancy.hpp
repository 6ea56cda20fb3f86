// Which constraints depend on the ones before them (redundant constraints, docs/algorithms.md
// sec. 5): the rule behind GA_REDUNDANT_DROP and behind the message of a singular start.
#pragma once

#include "matrix.hpp"

namespace ga {

// Walks the constraints in index order and keeps a constraint when its gradient (a row of
// Phi_q) is independent of the gradients kept before it: its part orthogonal to them exceeds
// 1e-10 of its norm. active[i] = 1 for the kept ones, 0 for the dependent ones (and for zero
// gradients). Returns the rank, or -1 when the matrix is too large for the method at hand:
// a dense Gram-Schmidt for dense Jacobians (n m <= 4e6), a sparse QR with the columns of
// Phi_q^T in their given order (SuiteSparseQR, Heath's rank detection) for declared patterns.
int independent_in_order(const ModelMatrix &J, int n, int m, unsigned char *active);

}  // namespace ga
