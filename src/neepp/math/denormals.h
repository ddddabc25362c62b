// Flush-to-zero and denormals-are-zero for the calling thread while an object of this type lives.
// Embree asks for both (its kernels slow down sharply on denormal operands, which long paths' tiny
// throughputs produce), and no radiance estimate needs values below 1e-38. The previous mode is
// restored, since TBB hands the same worker threads to other code.
#pragma once
#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define NEEPP_HAVE_MXCSR 1
#endif

namespace neepp {

class DenormalsAreZero {
public:
#ifdef NEEPP_HAVE_MXCSR
    DenormalsAreZero() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | kFlushToZero | kDenormalsAreZero); }
    ~DenormalsAreZero() { _mm_setcsr(saved_); }
#endif
    DenormalsAreZero(const DenormalsAreZero &) = delete;
    DenormalsAreZero &operator=(const DenormalsAreZero &) = delete;

private:
#ifdef NEEPP_HAVE_MXCSR
    static constexpr unsigned kFlushToZero = 0x8000, kDenormalsAreZero = 0x0040;
    unsigned saved_;
#endif
};

}  // namespace neepp
