"""Build hook: a wheel carries the top-level ``prompts/`` and ``data/`` files the package reads.

The checkout's ``prompts/`` and ``data/`` stay the source; ``build_py`` copies the files a run needs
into ``specrefine/_shipped/`` of the build, where :mod:`specrefine.core.paths` finds them when no
checkout is around.  Everything else is in ``pyproject.toml``.
"""

from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
SHIPPED = {"prompts": ["*.md"], "data": ["mazes/*.maze", "policies/*.pt", "vlm/README.md"]}


class BuildWithShippedFiles(build_py):
    def run(self):
        super().run()
        for folder, patterns in SHIPPED.items():
            for pattern in patterns:
                for src in sorted((ROOT / folder).glob(pattern)):
                    dst = Path(self.build_lib) / "specrefine" / "_shipped" / src.relative_to(ROOT)
                    self.mkpath(str(dst.parent))
                    self.copy_file(str(src), str(dst))


setup(cmdclass={"build_py": BuildWithShippedFiles})
