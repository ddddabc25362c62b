"""Writes hair_reference.inc: Mitsuba 3's own eval, pdf and sample of its `hair` BSDF for the
configurations that mitsuba_reference_test.cpp builds, in radiance transport (Mitsuba evaluates the
model the same way in both modes; neepp carries its adjoint in importance transport, hair.h).

Directions are in the shading frame, where the fibre runs along y and the normal is z: the incident ones
cover the front (z > 0) at several longitudinal angles and offsets across the fibre, and the back.

Run with the Python that has the mitsuba package (scripts/test.sh installs it in .venv):
    .venv/bin/python tests/materials/generate_hair_reference.py > tests/materials/hair_reference.inc
"""
import math

import mitsuba as mi

mi.set_variant("scalar_rgb")

from generate_principled_reference import print_references, unit  # noqa: E402

# Names and parameters; the C++ test builds the same (make_bsdfs in mitsuba_reference_test.cpp).
CONFIGS = {
    "hair_default": {},
    # The pigments of Mitsuba's two documentation scenes (bsdf_hair_blonde.xml, bsdf_hair_brown.xml).
    "hair_blonde": {"eumelanin": 0.3, "pheomelanin": 0.2},
    "hair_red": {"eumelanin": 0.01, "pheomelanin": 1.6},
    "hair_sigma_a": {"sigma_a": {"type": "rgb", "value": [0.2, 0.25, 0.7]}, "scale": 2.0,
                     "longitudinal_roughness": 0.2, "azimuthal_roughness": 0.5, "scale_tilt": 4.0,
                     "int_ior": 1.4},
    "hair_white_rough": {"sigma_a": {"type": "rgb", "value": [0.0, 0.0, 0.0]},
                         "longitudinal_roughness": 0.6, "azimuthal_roughness": 0.7, "scale_tilt": 0.0},
}


def fibre(theta_deg, gamma_deg):
    """The direction at longitudinal angle theta (from the plane normal to the fibre) whose projection on
    that plane is gamma from the normal, toward -x."""
    t, g = math.radians(theta_deg), math.radians(gamma_deg)
    return unit(-math.sin(g) * math.cos(t), math.sin(t), math.cos(g) * math.cos(t))


WIS = [fibre(0, 0), fibre(25, 35), fibre(-50, -60), fibre(70, 10), fibre(15, 140)]
WOS = [fibre(-25, 35), fibre(-20, -40), fibre(10, 170), fibre(-5, 200), fibre(60, 90), fibre(-70, -120),
       fibre(0, 0), fibre(30, -150)]
SAMPLES = [(0.02, (0.2, 0.7)), (0.15, (0.6, 0.1)), (0.33, (0.9, 0.95)), (0.5, (0.3, 0.4)),
           (0.68, (0.75, 0.5)), (0.85, (0.1, 0.85)), (0.995, (0.45, 0.25))]


def main():
    print_references("generate_hair_reference.py", [(n, "hair", p) for n, p in CONFIGS.items()],
                     modes=("Radiance",), wis=WIS, wos=WOS, samples=SAMPLES)


if __name__ == "__main__":
    main()
