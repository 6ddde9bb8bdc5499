// Progress of a raytraced render (`apparent raytrace`, `apparent figure`): rows traced over all
// rows of all frames and models, the time spent and the time left, on stderr. A terminal gets one
// line rewritten at most 5 times a second; anything else (a log file) a line every 10 s, so short
// runs print nothing there. Silent when disabled (--quiet). rowDone() may be called from any thread.
#pragma once

#include <atomic>
#include <chrono>
#include <iosfwd>
#include <mutex>
#include <string>

namespace apparent {

class TraceProgress {
public:
    // total_rows: image rows over every frame the command traces (> 0).
    TraceProgress(std::ostream& err, bool enabled, long long total_rows);

    // What is being traced now, e.g. "relativistic frame 12" (call between frames).
    void setLabel(const std::string& label);
    void rowDone();
    // Ends a terminal line (after the last row).
    void finish();

private:
    void print(long long done, double elapsed);

    std::ostream& err_;
    bool enabled_, terminal_;
    long long total_;
    std::atomic<long long> done_{0};
    std::mutex mutex_;
    std::string label_;
    std::chrono::steady_clock::time_point start_;
    std::atomic<double> last_{0};
    bool printed_ = false;
};

}  // namespace apparent
