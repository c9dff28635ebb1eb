"""``python -m sgtool``: the ``sgtool`` command (for an environment without its script,
such as a virtual environment layered on another that holds sgtool)."""

from sgtool.cli import main

if __name__ == "__main__":
    main()
