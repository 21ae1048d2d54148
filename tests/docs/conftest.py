import sys
from pathlib import Path

# the scripts under docs/ that generate a page or a figure are imported by the tests as modules
sys.path.append(str(Path(__file__).resolve().parents[2] / "docs"))
