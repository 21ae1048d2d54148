"""Moved modules keep their old import paths (thin re-exports of the same objects), and the
library layers never import the agent layer."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_old_paths_re_export_the_moved_modules():
    from cogmap import compare, demo_models, explore
    from cogmap.baselines import runner
    from cogmap.genmodel import demo_models as new_models
    from cogmap.harness import Episode, coverage_tracker
    from cogmap.inference import compare as new_compare

    for name in ("compare_inference", "format_table", "generate_sequence", "load_model", "Row", "Sequence"):
        assert getattr(compare, name) is getattr(new_compare, name)
    for name in ("MODELS", "tmaze", "corridor", "random_model"):
        assert getattr(demo_models, name) is getattr(new_models, name)
    assert explore.Episode is Episode and explore.coverage_tracker is coverage_tracker
    assert runner.coverage_tracker is coverage_tracker


def test_libraries_do_not_import_the_agent_layer():
    libs = {"cogmap.genmodel", "cogmap.inference", "cogmap.planning", "cogmap.envs"}
    bad = []
    for pkg in ("genmodel", "inference", "planning", "envs"):
        for path in (ROOT / pkg).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                names = []
                if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
                elif isinstance(node, ast.Import):
                    names = [a.name for a in node.names]
                for n in names:  # "from cogmap import inference" names cogmap.inference: allowed
                    if n.startswith("cogmap.") and not any(n == lib or n.startswith(lib + ".") for lib in libs):
                        bad.append(f"{path.relative_to(ROOT)}: {n}")
    assert bad == []
