/* libFuzzer harness over the C API: each input is one sequence of API calls (sizes, patterns,
 * options, steps, checkpoints, failing callbacks) whose every choice comes from the input's
 * bytes, checked as tests/c/test_api_sequences.c checks its generated sequences, restart twin
 * included; each input twice, on the chain and on the chain with a rotor (a group block). Built
 * by -DGALPHA_FUZZ=ON with clang (scripts/fuzz.sh). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#define SEQ_FAIL(...) (fprintf(stderr, __VA_ARGS__), fputc('\n', stderr), abort())
#define SEQ_REQUIRE(cond)                                                                      \
    ((cond) ? (void)0 : (fprintf(stderr, "%s:%d: %s\n", __FILE__, __LINE__, #cond), abort()))
#include "../c/api_sequence.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    seq_stats stats = {0};
    run_sequence(0, data, size, &stats, 0);  /* the chain, as the corpus was found on */
    run_sequence(0, data, size, &stats, 1);  /* the same calls with a rotor on a group block */
    return 0;
}
