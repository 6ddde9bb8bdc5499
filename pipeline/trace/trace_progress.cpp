#include "pipeline/trace/trace_progress.h"

#include <iomanip>
#include <ostream>
#include <sstream>

#include <unistd.h>

namespace apparent {

TraceProgress::TraceProgress(std::ostream& err, bool enabled, long long total_rows)
    : err_(err), enabled_(enabled && total_rows > 0), terminal_(::isatty(2) != 0), total_(total_rows),
      start_(std::chrono::steady_clock::now()) {}

void TraceProgress::setLabel(const std::string& label) {
    std::lock_guard<std::mutex> lock(mutex_);
    label_ = label;
}

void TraceProgress::rowDone() {
    if (!enabled_) return;
    const long long done = ++done_;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double every = terminal_ ? 0.2 : 10.0;
    if (elapsed - last_.load(std::memory_order_relaxed) < every) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || elapsed - last_.load() < every) return;  // another thread is printing
    last_.store(elapsed);
    print(done, elapsed);
}

void TraceProgress::print(long long done, double elapsed) {
    const double share = double(done) / double(total_);
    std::ostringstream line;  // its own formatting: the stream's stays as it was
    line << (terminal_ ? "\r" : "") << "raytrace: " << label_ << ", " << std::fixed << std::setprecision(0)
         << 100 * share << "% of all rows, " << std::setprecision(1) << elapsed << " s, about "
         << (share > 0 ? elapsed * (1 - share) / share : 0.0) << " s left" << (terminal_ ? "   " : "\n");
    err_ << line.str() << std::flush;
    printed_ = true;
}

void TraceProgress::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (enabled_ && terminal_ && printed_) err_ << "\n" << std::flush;
}

}  // namespace apparent
