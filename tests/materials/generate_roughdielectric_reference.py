"""Writes roughdielectric_reference.inc: Mitsuba 3's own eval, pdf and sample of its `roughdielectric` BSDF
for the configurations that mitsuba_reference_test.cpp builds (GGX and Beckmann, isotropic and
anisotropic, visible-normal sampling on and off, eta above and below 1, with and without multipliers), in
both transport modes, from outside and inside, with the directions and random numbers of
generate_principled_reference.py.

Run with the Python that has the mitsuba package (scripts/test.sh installs it in .venv):
    .venv/bin/python tests/materials/generate_roughdielectric_reference.py > tests/materials/roughdielectric_reference.inc
"""
import mitsuba as mi

mi.set_variant("scalar_rgb")

from generate_principled_reference import print_references  # noqa: E402

# Names and parameters; the C++ test builds the same (make_bsdfs in mitsuba_reference_test.cpp).
CONFIGS = {
    "roughdielectric_default": {},  # beckmann, alpha 0.1, bk7 in air, visible normals
    "roughdielectric_ggx_water": {"distribution": "ggx", "alpha": 0.3, "int_ior": "water"},
    "roughdielectric_ggx_aniso": {"distribution": "ggx", "alpha_u": 0.1, "alpha_v": 0.4, "int_ior": 1.6},
    "roughdielectric_beckmann_aniso_novis": {"distribution": "beckmann", "alpha_u": 0.35, "alpha_v": 0.15,
                                             "int_ior": 1.7, "ext_ior": 1.2, "sample_visible": False},
    "roughdielectric_ggx_novis_tinted": {"distribution": "ggx", "alpha": 0.5, "sample_visible": False,
                                         "specular_reflectance": {"type": "rgb", "value": [0.9, 0.7, 0.5]},
                                         "specular_transmittance": {"type": "rgb", "value": [0.3, 0.6, 0.8]}},
    # eta < 1: the denser medium outside.
    "roughdielectric_beckmann_inverted": {"alpha": 0.25, "int_ior": 1.0, "ext_ior": 1.5},
}


def main():
    print_references("generate_roughdielectric_reference.py",
                     [(n, "roughdielectric", p) for n, p in CONFIGS.items()])


if __name__ == "__main__":
    main()
