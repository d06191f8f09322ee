#include "core/errors.h"

#include <cmath>

namespace dipper {

void require_positive(double value, const std::string& what, const std::string& where)
{
    if (!(std::isfinite(value) && value > 0.0))
        throw InputError(concat(what, " must be > 0 and finite; got ", value, " (", where, ")"));
}

void require_non_negative(double value, const std::string& what, const std::string& where)
{
    if (!(std::isfinite(value) && value >= 0.0))
        throw InputError(concat(what, " must be >= 0 and finite; got ", value, " (", where, ")"));
}

void require_in_range(double value, double lo, double hi, const std::string& what, const std::string& where)
{
    if (!(std::isfinite(value) && value >= lo && value <= hi))
        throw InputError(concat(what, " must be in [", lo, ", ", hi, "]; got ", value, " (", where, ")"));
}

}  // namespace dipper
