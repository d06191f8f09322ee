#include "core/files.h"

#include "core/errors.h"

#include <iomanip>

namespace dipper {

std::ofstream open_for_writing(const std::string& path)
{
    std::ofstream out(path);
    if (!out) throw InputError(concat("cannot open '", path, "' for writing"));
    out << std::setprecision(10);
    return out;
}

void finish_writing(std::ofstream& out, const std::string& path)
{
    out.flush();
    if (!out) throw InputError(concat("failed while writing '", path, "' (disk full?)"));
}

}  // namespace dipper
