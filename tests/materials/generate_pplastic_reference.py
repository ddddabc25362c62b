"""Writes pplastic_reference.inc: Mitsuba 3's own eval, pdf and sample of its `pplastic` BSDF (polarized
plastic, as the unpolarized scalar_rgb variant evaluates it) for the configurations that
mitsuba_reference_test.cpp builds, in both transport modes, from outside and inside, with the directions
and random numbers of generate_principled_reference.py.

Run with the Python that has the mitsuba package (scripts/test.sh installs it in .venv):
    .venv/bin/python tests/materials/generate_pplastic_reference.py > tests/materials/pplastic_reference.inc
"""
import mitsuba as mi

mi.set_variant("scalar_rgb")

from generate_principled_reference import print_references  # noqa: E402

# Names and parameters; the C++ test builds the same (make_bsdfs in mitsuba_reference_test.cpp).
CONFIGS = {
    "pplastic_default": {},  # beckmann, alpha 0.1, polypropylene in air, diffuse 0.5, visible normals
    # Mitsuba's documentation example.
    "pplastic_docs": {"diffuse_reflectance": {"type": "rgb", "value": [0.05, 0.03, 0.1]}, "alpha": 0.06},
    "pplastic_ggx_aniso_novis": {"distribution": "ggx", "alpha_u": 0.3, "alpha_v": 0.1, "eta": 1.6,
                                 "sample_visible": False, "specular_reflectance": 0.8,
                                 "diffuse_reflectance": {"type": "rgb", "value": [0.7, 0.4, 0.2]}},
}


def main():
    print_references("generate_pplastic_reference.py", [(n, "pplastic", p) for n, p in CONFIGS.items()])


if __name__ == "__main__":
    main()
