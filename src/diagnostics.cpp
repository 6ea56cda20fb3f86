#include "diagnostics.hpp"

#include <cstdarg>
#include <cstdio>
#include <cstring>

namespace ga {

ga_status Diagnostics::fail(ga_status status, const char *fmt, ...)
{
    std::va_list args;
    va_start(args, fmt);
    std::vsnprintf(text_, sizeof text_, fmt, args);
    va_end(args);
    return status;
}

void Diagnostics::append(const char *fmt, ...)
{
    const std::size_t used = std::strlen(text_);
    if (used + 1 >= sizeof text_)
        return;
    std::va_list args;
    va_start(args, fmt);
    std::vsnprintf(text_ + used, sizeof text_ - used, fmt, args);
    va_end(args);
}

}  // namespace ga
