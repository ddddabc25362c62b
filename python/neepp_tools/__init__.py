"""neepp_tools: helpers to run neepp and Mitsuba 3, read/write EXR, compute error metrics and reports.

Pure Python, no build step: put ``<repo>/python`` on ``sys.path`` (tests/python/conftest.py and
bench/bench_path.py do that).
"""
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
SHARED_DIR = REPO_ROOT.parent / "shared"
SCENES_DIR = SHARED_DIR / "scenes"

#: The six evaluation scenes with their reference renders (see shared/design/EVALUATION.md).
#: name -> (width, height, max_depth, reference file name)
REFERENCES = {
    "bathroom": (512, 512, 17, "bathroom_ref_512x512_d17.exr"),
    "classroom": (640, 360, 17, "classroom_ref_640x360_d17.exr"),
    "cornell-box": (512, 512, 17, "cornell-box_ref_512x512_d17.exr"),
    "living-room": (640, 360, 17, "living-room_ref_640x360_d17.exr"),
    "staircase": (360, 640, 17, "staircase_ref_360x640_d17.exr"),
    "veach-ajar": (640, 360, 17, "veach-ajar_ref_640x360_d17.exr"),
}


#: Attribution required wherever the CC-BY 3.0 scenes are shown (shared/scenes/SOURCES.md).
CREDITS = {
    "classroom": '"Japanese Classroom" by NovaZeeke, CC-BY 3.0 (scene via Benedikt Bitterli\'s Rendering Resources)',
    "staircase": '"The Wooden Staircase" by Wig42, CC-BY 3.0 (scene via Benedikt Bitterli\'s Rendering Resources)',
    "living-room": '"The Grey & White Room" by Wig42, CC-BY 3.0 (scene via Benedikt Bitterli\'s Rendering Resources)',
}
CC_BY_URL = "https://creativecommons.org/licenses/by/3.0/"


def credit(scene: str) -> str:
    """Attribution line for a scene ('' for the CC0 ones)."""
    return f"{CREDITS[scene]}, {CC_BY_URL}" if scene in CREDITS else ""


def scene_xml(scene: str, scenes_dir: Path = SCENES_DIR) -> Path:
    return Path(scenes_dir) / scene / "scene.xml"


def reference_path(scene: str, scenes_dir: Path = SCENES_DIR) -> Path:
    return Path(scenes_dir) / scene / "reference" / REFERENCES[scene][3]
