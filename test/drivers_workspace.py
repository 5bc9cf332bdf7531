"""The robot drivers' workspace for the robot tests (test/robot_drivers_rostest.py, test/test_robot_drivers.py):
scripts/build_drivers.sh builds it once from the source archives and caches it, so calling it again costs
nothing; it exits 3 when there are no sources."""
import os
import subprocess

PKG = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


class DriversUnavailable(Exception):
    """No driver sources: the robot tests report themselves skipped with this reason."""


def drivers_devel():
    """The drivers' devel_isolated folder; DriversUnavailable without sources, RuntimeError when the build
    fails."""
    p = subprocess.run([os.path.join(PKG, "scripts", "build_drivers.sh")], stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True)
    if p.returncode == 3:
        raise DriversUnavailable(p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "no driver sources")
    if p.returncode != 0:
        raise RuntimeError("scripts/build_drivers.sh failed:\n" + p.stderr[-3000:])
    return p.stdout.strip().splitlines()[-1]
