"""The `femcod` command of the wheel: replaces this process by the femcod program inside the
package (femcod/_native/bin/femcod), with the same arguments, so exit codes, signals and
output are the program's own. Kept outside the femcod package so that starting the
command does not import numpy (about 0.1 s)."""
import os
import sys


def program_path():
    """The femcod program shipped in the wheel."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "femcod", "_native", "bin", "femcod")


def main():
    program = program_path()
    if not os.access(program, os.X_OK):
        sys.stderr.write(f"femcod: the program of this installation is missing or not executable: {program}\n")
        return 5
    os.execv(program, [program] + sys.argv[1:])


if __name__ == "__main__":
    sys.exit(main())
