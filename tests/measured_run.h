// Runs the `apparent` command line in a child process, measured: its peak memory and wall time.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "run_command.h"

namespace testcli {

// Runs `apparent ARGS` in a child process: its exit code, stderr, peak RSS (getrusage of the
// child, bytes) and wall time, so that a refused input is shown to stay small and quick.
struct Measured {
    int code = -1;
    std::string err;
    long long peak_rss = 0;
    double seconds = 0;
};

// `timeout_seconds` > 0: the child is stopped by SIGALRM after that long (a hang, code 128 + 14).
inline Measured runMeasured(const std::vector<std::string>& args, unsigned timeout_seconds = 0) {
    int pipe_fd[2];
    EXPECT_EQ(::pipe(pipe_fd), 0);
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(pipe_fd[0]);
        if (timeout_seconds > 0) ::alarm(timeout_seconds);
        const CommandResult r = apparentRun(args);
        const ssize_t ignored = ::write(pipe_fd[1], r.err.data(), r.err.size());
        (void)ignored;
        ::_exit(r.code);
    }
    ::close(pipe_fd[1]);
    Measured m;
    char buf[4096];
    for (ssize_t n; (n = ::read(pipe_fd[0], buf, sizeof buf)) > 0;) m.err.append(buf, size_t(n));
    ::close(pipe_fd[0]);
    int status = 0;
    rusage usage{};
    ::wait4(pid, &status, 0, &usage);
    m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    m.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    m.peak_rss = (long long)usage.ru_maxrss * 1024;
    return m;
}

}  // namespace testcli
