// Per-solver error text: what failed, where, with which numbers. Fixed-size buffer, so that
// reporting a failure inside ga_step never allocates.
#pragma once

#include <cstddef>
#include <cstring>

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

    // Keep a message aside and put it back (a failure reported after later attempts).
    static constexpr std::size_t kSize = 512;
    void copy_to(char (&out)[kSize]) const { std::memcpy(out, text_, kSize); }
    void restore(const char (&in)[kSize]) { std::memcpy(text_, in, kSize); }

private:
    char text_[kSize] = {0};
};

}  // namespace ga
