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


# -- the import graph ---------------------------------------------------------------------------------
PACKAGES = {"cogmap": "cogmap", "cogmap.genmodel": "genmodel", "cogmap.inference": "inference",
            "cogmap.planning": "planning", "cogmap.envs": "envs"}


def _modules() -> dict[str, Path]:
    mods = {}
    for pkg, folder in PACKAGES.items():
        for path in (ROOT / folder).rglob("*.py"):
            parts = list(path.relative_to(ROOT / folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            mods[".".join([pkg, *parts])] = path
    return mods


def _type_checking_only(tree) -> set[int]:
    """Line numbers of the imports under ``if TYPE_CHECKING:`` (never run)."""
    lines = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", getattr(node.test, "attr", None)) == "TYPE_CHECKING":
            lines |= {n.lineno for b in node.body for n in ast.walk(b) if isinstance(n, ast.Import | ast.ImportFrom)}
    return lines


def import_graph() -> dict[str, set[str]]:
    """module -> the package modules it imports, at the top or inside functions (``from a import
    b`` names ``a.b`` when that is a module, else ``a``); imports under ``TYPE_CHECKING`` do not run."""
    mods = _modules()
    graph = {m: set() for m in mods}
    for mod, path in mods.items():
        tree = ast.parse(path.read_text())
        skip = _type_checking_only(tree)
        package = mod.split(".") if path.name == "__init__.py" else mod.split(".")[:-1]
        for node in ast.walk(tree):
            if getattr(node, "lineno", None) in skip:
                continue
            if isinstance(node, ast.Import):
                graph[mod] |= {a.name for a in node.names if a.name in mods}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(package[: len(package) - node.level + 1] + ([node.module] if node.module else []))
                for a in node.names:
                    target = f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base
                    if target in mods and target != mod:
                        graph[mod].add(target)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def test_the_cycle_finder_finds_a_cycle_through_a_function_level_import():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(graph) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
    graph = import_graph()
    assert "cogmap.envs.buildings" in graph["cogmap.envs.layouts"]  # imported inside _building()


def test_the_package_has_no_import_cycle():
    found = cycles(import_graph())
    assert found == [], "import cycles: " + "; ".join(" <-> ".join(c) for c in found)


def test_no_private_name_is_imported_from_another_module():
    bad = []
    for mod, path in _modules().items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                bad += [f"{mod}: {node.module} {a.name}" for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")]
    assert bad == []


def test_inference_planning_and_envs_import_only_genmodel_of_each_other():
    graph = import_graph()
    libs = ("cogmap.inference", "cogmap.planning", "cogmap.envs")
    bad = sorted(f"{m} -> {t}" for m, targets in graph.items() for t in targets for lib in libs
                 if m.startswith(lib) and any(t.startswith(o) for o in libs if o != lib))
    assert bad == []


def _self_attributes(cls: ast.ClassDef) -> set[str]:
    """Names ``X`` of every ``self.X = ...`` (also augmented or annotated) in the class body."""
    out = set()
    for node in ast.walk(cls):
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
            node, ast.AnnAssign | ast.AugAssign) else []
        for t in targets:
            for e in ast.walk(t):
                if isinstance(e, ast.Attribute) and isinstance(e.value, ast.Name) and e.value.id == "self":
                    out.add(e.attr)
    return out


def test_agent_layer_classes_stay_small():
    """No class of the agent layer (``cogmap/`` outside the four libraries) spans more than 300 lines
    or sets more than 10 attributes on ``self``: its state belongs in records, its maths in functions."""
    libs = {"genmodel", "inference", "planning", "envs"}
    big = []
    for path in (ROOT / "cogmap").rglob("*.py"):
        if path.relative_to(ROOT / "cogmap").parts[0] in libs:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef):
                lines, attrs = node.end_lineno - node.lineno + 1, len(_self_attributes(node))
                if lines > 300 or attrs > 10:
                    big.append(f"{path.relative_to(ROOT)}:{node.name} ({lines} lines, {attrs} attributes)")
    assert big == []


def test_the_class_size_check_sees_lines_and_attributes():
    tree = ast.parse("class A:\n    def __init__(self):\n" + "".join(f"        self.a{i} = {i}\n" for i in range(11)))
    assert len(_self_attributes(tree.body[0])) == 11
