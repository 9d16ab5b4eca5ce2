"""Write every body's shape as `<name>.obj` + `<name>.mtl` into a folder:
``python -m world.actors.shapes.export assets/shapes`` (`make assets`)."""

from __future__ import annotations

import sys
from pathlib import Path

from world.actors.shapes.catalogue import bodies
from world.actors.shapes.obj import mtl_text, obj_text


def export(folder: Path) -> list[Path]:
    """Write the files into `folder` (created if missing); the paths written."""
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name, body in bodies().items():
        for path, text in ((folder / f"{name}.obj", obj_text(body)),
                           (folder / f"{name}.mtl", mtl_text(body))):
            path.write_text(text, encoding="utf-8", newline="\n")
            written.append(path)
    return written


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python -m world.actors.shapes.export FOLDER", file=sys.stderr)
        return 2
    print(f"wrote {len(export(Path(argv[0])))} files into {argv[0]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
