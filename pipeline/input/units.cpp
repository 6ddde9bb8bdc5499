#include "pipeline/input/units.h"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace apparent {

TimePrefix timePrefixFor(double largest) {
    const double a = std::fabs(largest);
    if (!(a < 1) || a == 0) return {"s", 1};
    if (a >= 1e-3) return {"ms", 1e-3};
    if (a >= 1e-6) return {"us", 1e-6};
    return {"ns", 1e-9};
}

std::string timeText(double t, const TimePrefix& prefix, int decimals) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(decimals) << t / prefix.seconds << " " << prefix.name;
    return s.str();
}

}  // namespace apparent
