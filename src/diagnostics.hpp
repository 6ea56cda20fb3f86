// Per-solver error text: what failed, where, with which numbers. Fixed-size buffer, so that
// reporting a failure inside ga_step never allocates.
#pragma once

#include "galpha.h"

namespace ga {

class Diagnostics {
public:
    // Record a message and return `status`, so that failures read `return diag.fail(...)`.
    ga_status fail(ga_status status, const char *fmt, ...)
#if defined(__GNUC__)
        __attribute__((format(printf, 3, 4)))
#endif
        ;
    // Add context to the message recorded last (e.g. where in the step it happened).
    void append(const char *fmt, ...)
#if defined(__GNUC__)
        __attribute__((format(printf, 2, 3)))
#endif
        ;
    void clear() { text_[0] = '\0'; }
    const char *text() const { return text_; }

private:
    char text_[512] = {0};
};

}  // namespace ga
