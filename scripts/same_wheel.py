"""CI's check that a checkout without symlinks builds the same wheel as one with them.

Clones the repository's HEAD twice, with ``core.symlinks`` true and false (Windows' default,
where a link becomes a small text file), builds the wheel of each as pip builds it, and compares
their files by name and content (the RECORD aside, which lists the same hashes). Exits 1 with
the differences. Usage: ``python scripts/same_wheel.py`` from anywhere in the repository.
"""

from __future__ import annotations

import hashlib
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def wheel_of(symlinks: bool, scratch: Path) -> dict[str, str]:
    """The files of the wheel built from a fresh clone of HEAD: name -> sha256."""
    checkout = scratch / f"symlinks-{symlinks}"
    subprocess.run(
        [
            "git",
            "clone",
            "-q",
            "--no-hardlinks",
            "-c",
            f"core.symlinks={str(symlinks).lower()}",
            str(ROOT),
            str(checkout),
        ],
        check=True,
    )
    out = scratch / f"wheel-{symlinks}"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(out), str(checkout)],
        check=True,
    )
    (built,) = out.glob("*.whl")
    with zipfile.ZipFile(built) as z:
        return {
            n: hashlib.sha256(z.read(n)).hexdigest()
            for n in z.namelist()
            if not n.endswith("/RECORD")
        }


def main() -> int:
    with tempfile.TemporaryDirectory() as scratch:
        linked, plain = wheel_of(True, Path(scratch)), wheel_of(False, Path(scratch))
    differ = sorted(n for n in linked.keys() & plain.keys() if linked[n] != plain[n])
    missing, extra = sorted(linked.keys() - plain.keys()), sorted(plain.keys() - linked.keys())
    if differ or missing or extra:
        print(
            f"core.symlinks=false builds another wheel: missing {missing}, extra {extra}, "
            f"different {differ}"
        )
        return 1
    print(f"core.symlinks=false builds the same wheel: {len(linked)} files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
