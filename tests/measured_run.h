// Runs the `apparent` command line in a child process, measured: its peak memory and wall time.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "run_command.h"

namespace testcli {

// Runs `apparent ARGS` in a child process: its exit code, stderr, peak memory and wall time, so
// that a refused input is shown to stay small and quick. The child is a fork of the test process,
// which may itself hold hundreds of MB by then (and getrusage's peak of a forked child counts
// them), so peak_rss is what the command added: the child's peak resident size (VmHWM, reset to
// its resident size at the start by /proc/self/clear_refs) less its resident size at the start.
struct Measured {
    int code = -1;
    std::string err;
    long long peak_rss = 0;
    double seconds = 0;
};

// A field of /proc/self/status in bytes ("VmRSS", "VmHWM"); 0 when it cannot be read.
inline long long procStatusBytes(const std::string& field) {
    std::ifstream in("/proc/self/status");
    std::string key;
    long long kib = 0;
    while (in >> key) {
        if (key == field + ":" && in >> kib) return kib * 1024;
        std::getline(in, key);
    }
    return 0;
}

// `timeout_seconds` > 0: the child is stopped by SIGALRM after that long (a hang, code 128 + 14).
inline Measured runMeasured(const std::vector<std::string>& args, unsigned timeout_seconds = 0) {
    int pipe_fd[2];
    EXPECT_EQ(::pipe(pipe_fd), 0);
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(pipe_fd[0]);
        if (timeout_seconds > 0) ::alarm(timeout_seconds);
        // Step: the peak from here on (clear_refs 5 resets VmHWM to VmRSS).
        std::ofstream("/proc/self/clear_refs") << "5";
        const long long start_rss = procStatusBytes("VmRSS");
        const CommandResult r = apparentRun(args);
        const long long added = std::max(0LL, procStatusBytes("VmHWM") - start_rss);
        ssize_t ignored = ::write(pipe_fd[1], &added, sizeof added);
        ignored = ::write(pipe_fd[1], r.err.data(), r.err.size());
        (void)ignored;
        ::_exit(r.code);
    }
    ::close(pipe_fd[1]);
    Measured m;
    char buf[4096];
    std::string bytes;
    for (ssize_t n; (n = ::read(pipe_fd[0], buf, sizeof buf)) > 0;) bytes.append(buf, size_t(n));
    ::close(pipe_fd[0]);
    int status = 0;
    ::waitpid(pid, &status, 0);
    m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    m.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    // A child stopped before it wrote (a hang: SIGALRM) leaves peak_rss 0 and err empty.
    if (bytes.size() >= sizeof m.peak_rss) {
        std::memcpy(&m.peak_rss, bytes.data(), sizeof m.peak_rss);
        m.err = bytes.substr(sizeof m.peak_rss);
    }
    return m;
}

}  // namespace testcli
