// ga::TangentProduct: A T(xi), a user matrix times the tangent operator on the columns of the
// rotations (docs/algorithms.md sec. 13, 14) -- K_t, Phi_q and Z where the step's q moves as
// q_n o exp(xi). Dense: a copy, multiplied in place. With a declared pattern: every entry in
// a rotation's column spreads over the columns of that rotation (3; a pose's 6), so the product
// has the expanded pattern (whole column blocks), fixed at setup; each refactorization scatters the
// entries with T's coefficients (no allocation, linear in the entries).
#pragma once

#include <vector>

#include "configuration_space.hpp"
#include "matrix.hpp"

namespace ga {

class TangentProduct {
public:
    // The layout of A T for A's layout (A's pattern expanded); allocates.
    void setup(const ModelMatrix &A, const ConfigurationSpace &space);
    // out() = A T(xi), or with xi null A itself in the expanded layout (T = I)
    void apply(const ModelMatrix &A, const Vec *xi, const ConfigurationSpace &space);
    // out() += J (-ad_v) T(xi) (xi null: T = I), the curvature's bracket (sec. 14) for a
    // product set up from J's layout: on patterns it spreads over the rotations' columns as
    // the product does (Model leaves it out of a Z on a pattern)
    void add_bracket(const ModelMatrix &J, const Vec &v, const Vec *xi,
                     const ConfigurationSpace &space);
    const ModelMatrix &out() const { return out_; }

private:
    ModelMatrix out_;
    // per entry of A: its first target in out_ (the group block's columns are consecutive
    // entries there), the block it is in (-1: a vector column, one target) and its place
    std::vector<int> target_, rotation_, local_;
    std::vector<double> T_;      // width^2 per group block, from offset_[block]
    std::vector<int> offset_;
};

}  // namespace ga
