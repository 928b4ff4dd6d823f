"""python3 -m relief_snake_batch MANIFEST.json --out DIR [options]: see cli.py and docs/batch.md."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
