// A file-size limit for one test's writes: while a FileSizeLimit lives, RLIMIT_FSIZE's soft limit
// is `bytes` and SIGXFSZ is ignored, so a write past the limit fails with EFBIG instead of killing
// the process; both are restored when it goes. ok() is false when the limit could not be set.
#pragma once

#include <csignal>

#include <sys/resource.h>

namespace testio {

class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        struct sigaction ignore {};
        ignore.sa_handler = SIG_IGN;
        ::sigaction(SIGXFSZ, &ignore, &old_action_);
        ::getrlimit(RLIMIT_FSIZE, &old_limit_);
        rlimit limit = old_limit_;
        limit.rlim_cur = bytes;
        ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
    }
    ~FileSizeLimit() {
        ::setrlimit(RLIMIT_FSIZE, &old_limit_);
        ::sigaction(SIGXFSZ, &old_action_, nullptr);
    }
    FileSizeLimit(const FileSizeLimit&) = delete;
    FileSizeLimit& operator=(const FileSizeLimit&) = delete;
    bool ok() const { return ok_; }

private:
    struct sigaction old_action_ {};
    rlimit old_limit_{};
    bool ok_ = false;
};

}  // namespace testio
