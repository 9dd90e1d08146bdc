"""``python -m meshcore`` = the ``meshcore`` command."""

from .cli import console

if __name__ == "__main__":
    console()
