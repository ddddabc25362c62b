// The OBJ reader on arbitrary bytes: a SceneError is the expected answer to a bad file; anything else
// (a crash, a sanitizer report, a hang, a leak, memory out of proportion to the input) is a bug.
#include <exception>
#include "fuzz_input.h"
#include "neepp/io/obj_reader.h"

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        neepp::fuzz::write_seed(dir, "quad.obj",
                                "# every statement the reader knows\no quad\ng front\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl m\ns off\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"
                                "f -4//1 -3//1 -2//1\nf 1 3 4\n");
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    try {
        neepp::read_obj(neepp::fuzz::write_input(data, size, "mesh.obj"));
    } catch (const std::exception &) {
    }
    return 0;
}
