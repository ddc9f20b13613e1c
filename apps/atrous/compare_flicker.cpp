// The reference-free flicker measure of `atrous compare --sequence` (compare_flicker.h; docs/temporal.md,
// "Flicker without a reference").
#include "compare_flicker.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

#include <nlohmann/json.hpp>

#include "atrous/error.h"
#include "progress.h"
#include "atrous/io/sequence.h"
#include "atrous/temporal.h"

namespace atrous::cli {

SequenceImages sequenceImages(const std::string& dir, bool preferReference) {
    SequenceImages out;
    for (const std::string& frame : io::listSequenceFrames(dir)) {
        io::SequenceFrame f = io::loadSequenceFrame(frame);
        out.emplace_back(f.index, preferReference && !f.reference.empty() ? std::move(f.reference) : std::move(f.color));
    }
    return out;
}

FlickerGuide FlickerGuide::load(const std::string& dir, std::vector<std::string>* notes) {
    FlickerGuide g;
    g.mDir = dir;
    CameraFit previousCamera;
    Image previousColor;
    std::string how;  // how the motion was found, when not the renderer's
    for (const std::string& frame : io::listSequenceFrames(dir)) {
        io::SequenceFrame f = io::loadSequenceFrame(frame);
        if (f.motion.empty() && !f.position.empty()) {
            // No vectors but a Position pass (LuxCore): each frame's camera fitted to its positions.
            const CameraFit fit = fitCamera(f.position);
            f.motion = motionFromPositions(f.position, fit, previousCamera);
            previousCamera = fit;
            how = "from its Position pass (a camera fitted per frame)";
        } else if (f.motion.empty()) {
            // Neither: block matching on the colours, against the previous frame (the first has none).
            f.motion = estimateMotion(f.color, previousColor.empty() ? nullptr : &previousColor);
            previousColor = std::move(f.color);  // not kept for the guide
            how = "estimated from its colours (block matching): no depth, normal or id test";
        }
        g.mFrames[f.index] = Buffers{std::move(f.motion), std::move(f.depth), std::move(f.normal), std::move(f.ids)};
    }
    if (!how.empty() && notes) notes->push_back("note: " + dir + " has no motion vectors: the frames' motion " + how);
    return g;
}

FlickerMetrics FlickerGuide::measure(const SequenceImages& seq, const std::string& name) const {
    double rel = 0, reprojected = 0;
    int steps = 0;
    for (size_t i = 1; i < seq.size(); ++i) {
        const int t = seq[i].first, prev = seq[i - 1].first;
        if (prev != t - 1) continue;  // not consecutive (--step): no motion joins them
        for (int k : {prev, t})
            if (!has(k))
                throw InputError(name + ": frame " + std::to_string(k) + " has no frame of that number in " + mDir +
                                 " (the sequence whose motion vectors place the frames)");
        const Buffers& b = mFrames.at(t);
        const Buffers& a = mFrames.at(prev);
        Frame now, before;
        now.motion = &b.motion, now.depth = &b.depth, now.normal = &b.normal, now.ids = &b.ids;
        before.motion = &a.motion, before.depth = &a.depth, before.normal = &a.normal, before.ids = &a.ids;
        try {
            const FlickerMetrics m = computeFlicker(seq[i].second, seq[i - 1].second, now, before);
            rel += m.relMse * m.reprojected, reprojected += m.reprojected;
        } catch (const InputError& e) {
            throw InputError(name + ": frame " + std::to_string(t) + ": " + e.what() + " (" + mDir + ")");
        }
        ++steps;
    }
    FlickerMetrics m;
    if (steps > 0) m.relMse = reprojected > 0 ? rel / reprojected : 0.0, m.reprojected = reprojected / steps;
    return m;
}

void addFlickerOptions(CLI::App& cmd, bool& noReference, std::string& input) {
    cmd.add_flag("--no-reference", noReference,
                 "With --sequence: no reference; --sequence's folder and the others are ranked by the flicker measure "
                 "(each frame against the one before, warped by the motion vectors; docs/temporal.md)");
    cmd.add_option("--input", input, "With --sequence: the sequence that was denoised, whose motion, depth, normals and ids "
                                     "place the frames for the flicker measure (default: the sequence's own)");
}

void runFlickerCompare(const FlickerCompareArgs& a) {
    std::vector<std::string> notes;
    std::vector<SequenceImages> seqs;
    for (const std::string& dir : a.sequences) {
        seqs.push_back(sequenceImages(dir, false));
        if (seqs.back().size() < 2) throw InputError(dir + ": the flicker measure needs at least two frames");
    }
    const FlickerGuide guide = FlickerGuide::load(a.input.empty() ? a.sequences[0] : a.input, &notes);
    std::vector<FlickerMetrics> ms;
    for (size_t k = 0; k < seqs.size(); ++k) ms.push_back(guide.measure(seqs[k], a.sequences[k]));
    for (const std::string& n : notes) logLine("%s\n", n.c_str());
    std::vector<size_t> order(seqs.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return ms[x].relMse < ms[y].relMse; });
    if (a.json) {
        nlohmann::json j;
        j["reference"] = nullptr;
        j["guide"] = guide.dir();
        j["sequences"] = nlohmann::json::array();
        for (size_t k = 0; k < seqs.size(); ++k)
            j["sequences"].push_back({{"path", a.sequences[k]}, {"frames", seqs[k].size()}, {"flicker", ms[k].relMse},
                                      {"reprojected", ms[k].reprojected}});
        j["ranking"] = nlohmann::json::array();
        for (size_t k : order) j["ranking"].push_back(a.sequences[k]);
        resultLine("%s\n", j.dump(2).c_str());
        return;
    }
    resultLine("no reference: flicker = relMSE of each frame against the one before it, warped by the motion of %s, "
                "where it reprojects\n", guide.dir().c_str());
    resultLine("%-32s %7s %14s %12s\n", "sequence", "frames", "flicker", "reprojected");
    for (size_t k = 0; k < seqs.size(); ++k)
        resultLine("%-32s %7zu %14.6g %11.1f%%\n", a.sequences[k].c_str(), seqs[k].size(), ms[k].relMse,
                    100.0 * ms[k].reprojected);
    if (seqs.size() > 1) {
        resultLine("ranking (least flicker first):");
        for (size_t i = 0; i < order.size(); ++i) resultLine("%s %s", i ? "," : "", a.sequences[order[i]].c_str());
        resultLine("\n");
    }
}

}  // namespace atrous::cli
