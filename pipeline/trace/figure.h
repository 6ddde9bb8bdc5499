// `apparent figure` (pipeline/trace/figure.cpp): the paper's comparison sheet traced by the 4D raytracer
// (pipeline/trace/raytrace.h SceneTracer), a row per model and a column per frame (pipeline/trace/sheet.h lays
// it out), or the models side by side in a video; and the frames and labels of its columns.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "pipeline/input/units.h"
#include "pipeline/stage/stage.h"
#include "pipeline/trace/raytrace.h"
#include "pipeline/trace/sheet.h"

namespace apparent {

constexpr int kMaxFigureColumns = 64;

struct FigureSettings {
    StageOptions stage;            // scene, --max-frames, limits (the rows fix the models, the columns the frames)
    std::string out_path = "sheet.png";
    std::vector<Model> models;     // --models: the rows, top to bottom (empty: instant, finite, relativistic)
    int columns = 6;               // --columns: evenly spaced frames (figureFrames)
    std::vector<double> times;     // --times: the columns' camera times (nearest frame each)
    long long frame_from = -1, frame_to = -1;  // --frames A:B: columns A..B-1 (-1: unset; B -1: to the end)
    std::string title;             // --title: above the sheet, wrapped onto more lines when wider than it
    bool labels = true;            // row labels (model names) and column labels (camera times)
    // --row-labels, --column-labels: the labels instead of the model names (one per model, the
    // rows; a video's columns) and the camera times (one per column); empty: those.
    std::vector<std::string> row_labels, column_labels;
    bool frame_objects = false;    // --frame-objects: the camera aimed and its view fitted (framing.h)
    int samples = 0;               // --samples: rays per pixel (0: kDefaultFigureSamples, a video kDefaultRaytraceSamples)
    std::string video_path;        // --video: an MP4 of every frame in --frames, the models side by side
    int width = 320, height = 180;  // one panel
    int threads = 0;
    bool quiet = false;
    bool shade_doppler = false;    // --shade doppler, as raytrace's (SceneTracer::setShadeDoppler)
    double gate = 0;               // --gate DEPTH, as raytrace's (SceneTracer::setGate)
    long long max_slab_memory = kDefaultSlabMemory;  // --max-slab-memory, as raytrace's (the video's models share it)
};

// The frames a figure shows in its columns: evenly spaced over the scene's frames, first and last included.
std::vector<long long> figureFrames(const Scene& scene, int columns);

// The frame nearest to each camera time; false with the message for a time outside the scene's frames.
bool framesAtTimes(const Scene& scene, const std::vector<double>& times, std::vector<long long>* frames,
                   std::string* error);

// "t = 10.0 s": frame k's camera time with as many decimals as the frame rate needs (10 fps: 1,
// 12 or 30 fps: 2), as the figure labels its columns and video frames. The unit
// (cameraTimePrefix) is ms, us or ns when every frame time of the scene is below a second, a
// millisecond or a microsecond, and the decimals are counted in that unit.
std::string cameraTimeLabel(const Scene& scene, long long k);
TimePrefix cameraTimePrefix(const Scene& scene);

// `apparent figure`: the paper's comparison sheet, a row per model, a column per frame, labelled
// with model names and camera times, panels separated by 4-pixel grey lines; or with --video the
// models side by side in an MP4 of every frame in --frames. Exit 2 for a missing font or ffmpeg.
// Under mpirun the ranks share its pictures (the panels, or the video's frames) and rank 0 writes
// the sheet or video, byte-identical to one process's (pipeline/run/mpi_group.h).
int figure(const FigureSettings& settings, std::ostream& log, std::ostream& err);

}  // namespace apparent
