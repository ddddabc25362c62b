// The curve-file reader (Mitsuba's linearcurve and bsplinecurve) on arbitrary bytes, read with both
// bases: a SceneError is the expected answer to a bad file; anything else (a crash, a sanitizer report,
// a hang, a leak, memory out of proportion to the input) is a bug.
#include <exception>
#include "fuzz_input.h"
#include "neepp/io/curve_reader.h"

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        // Two curves (Mitsuba's documentation example): blanks, CRLF, a signed exponent, trailing text.
        neepp::fuzz::write_seed(dir, "two_curves.txt",
                                "-1.0 0.1 0.1 0.5\n-0.3 1.2 1.0 0.5\n 0.3 0.3 1.1 0.5\n1.0 1.4 1.2 0.5\n\n"
                                "-1.0 5.0 2.2 1\r\n-2.3 4.0 2.3 2\r\n\t3.3 3.0 2.2 3 extra\r\n4.0 2.0 2.3 4\r\n"
                                "4.0 1.0 2.2 5\n+4e0 0.0 2.3 6e-1\n");
        neepp::fuzz::write_seed(dir, "segment.txt", "0 0 0 0.1\n1 0 0 0\n");
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    const std::string path = neepp::fuzz::write_input(data, size, "curves.txt");
    for (neepp::CurveBasis basis : {neepp::CurveBasis::Linear, neepp::CurveBasis::BSpline}) {
        try {
            neepp::read_curves(path, basis);
        } catch (const std::exception &) {
        }
    }
    return 0;
}
