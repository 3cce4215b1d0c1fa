"""What the reports of experiments/*/report.py share: running a program that prints `key=value` lines, a
goal's verdict, the machine's CPU and a Debian package's version. Each report puts this folder on
`sys.path` and imports from here."""

import subprocess
import sys
from pathlib import Path


def run(command: list[str], env: dict[str, str] | None = None) -> dict[str, str]:
    """Runs `command` and returns its `key=value` output lines; exits naming the command if it fails."""
    done = subprocess.run(command, capture_output=True, text=True, check=False, env=env)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed: {done.stderr.strip()}")
    return dict(line.split("=", 1) for line in done.stdout.splitlines() if "=" in line)


def goal(what: str, ours: float, theirs: float, factor: float, digits: int = 1) -> str:
    """A goal `ours < factor · theirs`: reached, or missed by how much."""
    figures = f"{ours:.{digits}f} against {theirs:.{digits}f}"
    if ours < factor * theirs:
        return f"{what}: **reached** ({figures})."
    return f"{what}: **missed**, {ours / (factor * theirs):.2f}× over the goal ({figures})."


def dpkg_version(package: str) -> str:
    """The installed version of a Debian package, or "unknown"."""
    done = subprocess.run(["dpkg-query", "-W", "-f=${Version}", package], capture_output=True, text=True, check=False)
    return done.stdout.strip() or "unknown"


def cpu() -> str:
    """The CPU's model name."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"
