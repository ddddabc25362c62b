// Sample generators for the render loop. A sampler is set up for one (pixel, sample index) and then
// hands out the dimensions of that path in order; the same setup gives the same numbers on any thread.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include "neepp/math/vec.h"
#include "neepp/sampling/rng.h"

namespace neepp {

// The parts of a path that read their numbers from a stream of their own where a sampler keeps streams.
enum class SampleStream : uint8_t { Camera, Light, Connection, Roulette };
constexpr int kSampleStreams = 4;

class Sampler {
public:
    virtual ~Sampler() = default;
    virtual void start_sample(uint32_t px, uint32_t py, uint32_t sample_index) = 0;
    virtual float next_1d() = 0;
    virtual Vec2 next_2d() = 0;
    virtual std::unique_ptr<Sampler> clone() const = 0;
    virtual std::string name() const = 0;
    // Switches the numbers that follow to another stream (each stream continues where it left off) and
    // returns the one that was current. A sampler that mutates a path's numbers (PSSMLT's) keeps one
    // sequence per part of the path, so that a part that draws more or fewer numbers (a longer camera
    // subpath, a roulette taken or not) does not shift the numbers of the others; samplers with one
    // sequence ignore it.
    virtual SampleStream use_stream(SampleStream stream) { return stream; }
};

// Reads from `stream` for the scope's lifetime, then back to the stream that was current.
class StreamScope {
public:
    StreamScope(Sampler &sampler, SampleStream stream) : sampler_(sampler), previous_(sampler.use_stream(stream)) {}
    ~StreamScope() { sampler_.use_stream(previous_); }
    StreamScope(const StreamScope &) = delete;
    StreamScope &operator=(const StreamScope &) = delete;

private:
    Sampler &sampler_;
    SampleStream previous_;
};

// Independent uniform random numbers (Mitsuba's `independent`).
class IndependentSampler final : public Sampler {
public:
    explicit IndependentSampler(uint64_t seed) : seed_(seed) {}
    void start_sample(uint32_t px, uint32_t py, uint32_t sample_index) override {
        uint64_t pixel = (uint64_t(py) << 32) | px;
        rng_.seed(mix_bits(seed_ ^ mix_bits(pixel)), mix_bits(sample_index + (seed_ << 32)));
    }
    // Starts the sequence that PCG32(init_state, stream) gives, for a caller that derives its own seeds.
    void start_stream(uint64_t init_state, uint64_t stream) { rng_.seed(init_state, stream); }
    float next_1d() override { return rng_.next_float(); }
    Vec2 next_2d() override { return rng_.next_2d(); }
    std::unique_ptr<Sampler> clone() const override { return std::make_unique<IndependentSampler>(seed_); }
    std::string name() const override { return "independent"; }

private:
    uint64_t seed_;
    PCG32 rng_;
};

// Per-pixel randomized Sobol (Owen-scrambled, Laine-Karras hashing) over the sample index, with each
// dimension pair decorrelated by a hash. Low discrepancy in the first dimensions of each pixel.
class SobolSampler final : public Sampler {
public:
    explicit SobolSampler(uint64_t seed) : seed_(seed) {}
    void start_sample(uint32_t px, uint32_t py, uint32_t sample_index) override {
        pixel_hash_ = mix_bits(seed_ ^ mix_bits((uint64_t(py) << 32) | px));
        index_ = sample_index;
        dim_ = 0;
    }
    float next_1d() override;
    Vec2 next_2d() override;
    std::unique_ptr<Sampler> clone() const override { return std::make_unique<SobolSampler>(seed_); }
    std::string name() const override { return "sobol"; }

private:
    uint64_t seed_, pixel_hash_ = 0;
    uint32_t index_ = 0, dim_ = 0;
};

std::unique_ptr<Sampler> make_sampler(const std::string &name, uint64_t seed);

}  // namespace neepp
