"""Run every benchmark in bench/ (results in bench/results/)."""
import runpy
from pathlib import Path

for script in sorted(Path(__file__).parent.glob("*.py")):
    if script.name != "run.py" and not script.name.startswith("_"):
        print(f"== {script.name}", flush=True)
        runpy.run_path(str(script), run_name="__main__")
