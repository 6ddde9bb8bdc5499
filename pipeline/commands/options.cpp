#include <sstream>

#include <CLI/CLI.hpp>

#include "pipeline/commands/command.h"
#include "pipeline/input/scene.h"

namespace apparent {

int usageError(std::ostream& err, const std::string& message) {
    err << "error: " << message << "\n";
    return kExitBadInput;
}

bool parseFrames(const std::string& text, long long* from, long long* to) {
    const auto colon = text.find(':');
    if (colon == std::string::npos) return false;
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    try {
        size_t used = 0;
        *from = a.empty() ? 0 : std::stoll(a, &used);
        if (!a.empty() && used != a.size()) return false;
        *to = b.empty() ? -1 : std::stoll(b, &used);
        if (!b.empty() && used != b.size()) return false;
    } catch (const std::exception&) {
        return false;
    }
    return *from >= 0 && (*to < 0 || *to > *from);
}

bool parseSize(const std::string& text, int* width, int* height) {
    const auto x = text.find('x');
    if (x == std::string::npos) return false;
    try {
        size_t used_w = 0, used_h = 0;
        const long w = std::stol(text.substr(0, x), &used_w), h = std::stol(text.substr(x + 1), &used_h);
        if (used_w != x || used_h != text.size() - x - 1 || w < 1 || h < 1 || w > 16384 || h > 16384) return false;
        *width = int(w);
        *height = int(h);
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

std::string samplesProblem(int samples) {
    return "--samples: " + std::to_string(samples) + " is not a square from 1 to 256 (1, 4, 9, 16, ...)";
}

std::vector<std::string> splitLabels(const std::string& text) {
    std::vector<std::string> labels;
    if (text.empty()) return labels;
    labels.emplace_back();
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] == '\\' && i + 1 < text.size() && text[i + 1] == ',') {
            labels.back() += ',';
            ++i;
        } else if (text[i] == ',') {
            labels.emplace_back();
        } else {
            labels.back() += text[i];
        }
    }
    return labels;
}

bool parseModelList(const std::string& text, StageOptions* options, std::string* error) {
    std::stringstream ss(text);
    std::string item;
    while (!text.empty() && std::getline(ss, item, ',')) {
        Model m;
        if (item == "all") {
            options->all_models = true;
        } else if (parseModel(item, &m)) {
            options->models.push_back(m);
        } else {
            *error = "--model: unknown model '" + item + "' (instant, finite, relativistic, contracted, all)";
            return false;
        }
    }
    return true;
}

void addStageLimits(CLI::App* command, StageOptions* stage) {
    command->add_option("--max-frames", stage->max_frames, "Refuse scenes with more frames")->capture_default_str();
    command->add_option("--max-object-frames", stage->max_object_frames,
                        "Refuse runs whose objects (mirror reflections included) times frames exceed this")
        ->capture_default_str();
    command->add_flag("--allow-outside", stage->limits.allow_outside,
                      "Let scene mesh paths leave the scene's folder and the working folder");
}

std::string threadsProblem(long long n) {
    return "--threads: " + std::to_string(n) + " is outside 0 (all cores) .. " + std::to_string(kMaxThreads);
}

}  // namespace apparent
