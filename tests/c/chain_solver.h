/* A solver for the N-link chain with its declared patterns and callbacks, shared by the suites
 * that run it (include after cmocka.h). */
#ifndef GALPHA_TEST_CHAIN_SOLVER_H
#define GALPHA_TEST_CHAIN_SOLVER_H

#include <galpha.h>

#include "scenes/chain.h"

/* exact_tangent: K_t by callback; otherwise grouped finite differences at every matrix, not
 * only once they matter. */
static inline ga_solver *chain_solver(chain *c, int exact_tangent)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(3 * c->links, 2 * c->links, &s), GA_OK);
    assert_int_equal(chain_declare_patterns(c, s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, chain_mass, chain_force, chain_constraint,
                                      chain_jacobian, c),
                     GA_OK);
    if (exact_tangent)
        assert_int_equal(ga_set_tangents(s, chain_stiffness, NULL), GA_OK);
    else
        assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
    return s;
}

/* The chain on the sparse path in the given formulation, exact K_t, with force and Jacobian
 * callbacks of the test's (wrappers that inject faults or record what they see). */
static inline ga_solver *sparse_chain_solver(chain *c, ga_force_fn force, ga_jacobian_fn jacobian,
                                             int formulation)
{
    ga_solver *s = chain_solver(c, 1);
    assert_int_equal(ga_set_callbacks(s, chain_mass, force, chain_constraint, jacobian, c), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    return s;
}

#endif
