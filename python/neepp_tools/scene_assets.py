"""Files the project's scenes (scenes/) need that are generated, not committed, and the scripts that make them.

A scene whose binary input is made by a script beside it (scenes/smoke-plume/make_plume.py writes
plume.vol) lists it in GENERATED; ``ensure_scene_assets(scene)`` runs the script when a file is missing
and returns the files, so every consumer (the tests, a benchmark) can call it before rendering:

    from neepp_tools.scene_assets import ensure_scene_assets
    ensure_scene_assets("smoke-plume")      # writes scenes/smoke-plume/plume.vol if it is not there

From a shell: ``.venv/bin/python -m neepp_tools.scene_assets`` (with python/ on PYTHONPATH) makes every
scene's files. The generators are deterministic (the same bytes each run) and write atomically, so
concurrent callers are harmless.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from . import REPO_ROOT

PROJECT_SCENES = REPO_ROOT / "scenes"

#: scene folder -> (generator script in it, the files it writes there)
GENERATED: dict[str, tuple[str, tuple[str, ...]]] = {
    "smoke-plume": ("make_plume.py", ("plume.vol",)),
}


def ensure_scene_assets(scene: str, *, force: bool = False, scenes_dir: Path = PROJECT_SCENES,
                        python: str | None = None, timeout: float = 300) -> list[Path]:
    """The generated files of scenes_dir/scene, made first by its generator if one is missing (or with
    force). A scene with no generated files gives []. Raises RuntimeError if the generator fails or does not
    write them."""
    if scene not in GENERATED:
        return []
    script, names = GENERATED[scene]
    folder = Path(scenes_dir) / scene
    files = [folder / n for n in names]
    if force or not all(f.is_file() for f in files):
        r = subprocess.run([python or sys.executable, str(folder / script)], capture_output=True, text=True,
                           timeout=timeout)
        missing = [str(f) for f in files if not f.is_file()]
        if r.returncode != 0 or missing:
            raise RuntimeError(f"{folder / script} failed (rc={r.returncode}; missing {missing}):\n"
                               f"{r.stdout[-2000:]}{r.stderr[-2000:]}")
    return files


def ensure_all(force: bool = False) -> list[Path]:
    """Every project scene's generated files."""
    return [f for scene in GENERATED for f in ensure_scene_assets(scene, force=force)]


if __name__ == "__main__":
    for f in ensure_all(force="--force" in sys.argv[1:]):
        print(f)
