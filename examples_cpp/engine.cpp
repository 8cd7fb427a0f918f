// engine.cpp: the cloth as a game engine runs it. A simulation thread steps the underwater towel
// (FC_PRESET_UNDERWATER, 61 x 41) once per 60 Hz tick while its top edge swings, and publishes
// positions and normals into a double buffer; a render thread reads the newest complete frame
// whenever it draws (never a half-written one). One tick is refused on purpose (the pins are
// thrown a kilometre away, as a broken animation would): the engine keeps the last good frame
// on screen, reports the status and the library's message, puts the pins back and goes on.
//
// Prints the frames simulated, refused and published, what the renderer saw, what a tick's step
// cost (median and worst, ms; reported, never asserted) and the last published corner.
// Usage: engine [ticks] [--realtime] [--xpbd]  (default 240 ticks, as fast as the CPU goes;
// --realtime paces the ticks at 60 Hz as a game would; --xpbd steps the preset with
// FC_INTEGRATOR_XPBD, about half the cost a tick: docs/realtime.md).
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <mutex>
#include <numeric>
#include <thread>
#include <vector>

#include "fraccloth.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTick = 1.0 / 60.0;

/// One frame for the renderer: what the simulation published, and which tick it was.
struct Frame {
    std::vector<float> positions, normals;
    long tick = -1;
};

/// Two frames: the simulation fills the back one with no lock held, then swaps it to the front
/// under the lock; the renderer copies the front under the same lock.
class DoubleBuffer {
public:
    explicit DoubleBuffer(std::size_t floats) {
        for (Frame& f : frames_) {
            f.positions.assign(floats, 0.0f);
            f.normals.assign(floats, 0.0f);
        }
    }
    Frame& back() { return frames_[1 - front_]; }
    void publish() {
        std::lock_guard<std::mutex> lock(mutex_);
        front_ = 1 - front_;
    }
    /// Copies the newest published frame into `out`; false before the first.
    bool read(Frame& out) {
        std::lock_guard<std::mutex> lock(mutex_);
        const Frame& f = frames_[front_];
        if (f.tick < 0) return false;
        out.positions = f.positions;
        out.normals = f.normals;
        out.tick = f.tick;
        return true;
    }

private:
    std::mutex mutex_;
    Frame frames_[2];
    int front_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
    const long ticks = argc > 1 ? std::atol(argv[1]) : 240;
    bool realtime = false, xpbd = false;
    for (int a = 2; a < argc; ++a) {
        realtime = realtime || std::strcmp(argv[a], "--realtime") == 0;
        xpbd = xpbd || std::strcmp(argv[a], "--xpbd") == 0;
    }
    if (ticks < 2) return 2;
    try {
        FcClothDesc desc = fraccloth::preset_desc(FC_PRESET_UNDERWATER);
        if (xpbd) desc.integrator = FC_INTEGRATOR_XPBD;
        fraccloth::Cloth cloth = fraccloth::Cloth::grid(desc);
        // The engine's own threads: the cloth steps on the calling (simulation) thread only.
        cloth.set_threads(1);
        std::vector<uint32_t> top(desc.width);
        std::iota(top.begin(), top.end(), 0u);
        cloth.set_pinned(top);
        const std::vector<float> rest = cloth.positions();
        const std::size_t floats = rest.size();
        DoubleBuffer buffer(floats);
        std::atomic<bool> running{true};

        // The render thread: draws whatever is newest, checking that every frame it sees is
        // whole (finite, unit normals) and never older than the one before.
        std::atomic<long> reads{0}, torn{0}, backwards{0};
        std::thread render([&] {
            Frame seen;
            long last = -1;
            while (running.load()) {
                if (buffer.read(seen)) {
                    ++reads;
                    if (seen.tick < last) ++backwards;
                    last = seen.tick;
                    for (std::size_t k = 0; k + 2 < floats; k += 3) {
                        const float n2 = seen.normals[k] * seen.normals[k] + seen.normals[k + 1] * seen.normals[k + 1] +
                                         seen.normals[k + 2] * seen.normals[k + 2];
                        if (!std::isfinite(seen.positions[k]) || std::fabs(n2 - 1.0f) > 1e-3f) {
                            ++torn;
                            break;
                        }
                    }
                }
                std::this_thread::sleep_for(std::chrono::microseconds(200));
            }
        });

        // The simulation thread (this one): one step per tick.
        std::vector<float> targets(3 * top.size());
        long refused = 0, published = 0;
        std::vector<double> step_ms;
        const long broken = ticks / 2;  // the tick whose pins an animation bug throws away
        auto next = std::chrono::steady_clock::now();
        for (long tick = 1; tick <= ticks; ++tick) {
            const double t = static_cast<double>(tick) * kTick;
            for (std::size_t i = 0; i < top.size(); ++i) {
                targets[3 * i + 0] = rest[3 * top[i] + 0];
                targets[3 * i + 1] = rest[3 * top[i] + 1];
                targets[3 * i + 2] = static_cast<float>(0.04 * std::sin(2.0 * kPi * 0.5 * t));
                if (tick == broken) targets[3 * i + 2] += 1000.0f;
            }
            cloth.set_pin_targets(top, targets);
            try {
                const auto begun = std::chrono::steady_clock::now();
                cloth.step(kTick);
                step_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begun).count());
            } catch (const fraccloth::Error& e) {
                // Refused: the cloth is exactly as it was; the last good frame stays on screen.
                ++refused;
                std::printf("tick %ld refused: status %d: %.120s\n", tick, static_cast<int>(e.status()), e.what());
                continue;
            }
            Frame& back = buffer.back();
            cloth.positions(back.positions);
            back.normals = cloth.normals();
            back.tick = tick;
            buffer.publish();
            ++published;
            if (realtime) {
                next += std::chrono::microseconds(16667);
                std::this_thread::sleep_until(next);
            }
        }
        running = false;
        render.join();

        Frame last;
        buffer.read(last);
        const std::size_t corner = floats / 3 - desc.width;
        std::printf("ticks %ld refused %ld published %ld\n", ticks, refused, published);
        std::printf("render reads %ld torn %ld backwards %ld\n", reads.load(), torn.load(), backwards.load());
        std::sort(step_ms.begin(), step_ms.end());
        if (!step_ms.empty())
            std::printf("step_ms median %.3f worst %.3f\n", step_ms[step_ms.size() / 2], step_ms.back());
        std::printf("last tick %ld\n", last.tick);
        std::printf("corner %zu %.9g %.9g %.9g\n", corner, last.positions[3 * corner], last.positions[3 * corner + 1],
                    last.positions[3 * corner + 2]);
        return 0;
    } catch (const fraccloth::Error& e) {
        std::fprintf(stderr, "fraccloth: %s\n", e.what());
        return 1;
    }
}
