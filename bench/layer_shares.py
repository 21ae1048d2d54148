"""How much of each system's code lives in the agent layer (``cogmap/``) and how much in the four
libraries, counted in lines:

    python bench/layer_shares.py

For each system: its agent-layer package alone, and with its study modules (``cogmap/study/``);
the library modules are those that exist for that system (listed below).
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SYSTEMS = {
    "DVBF-LM": {
        "agent": ["cogmap/dvbf/*.py"],
        "studies": ["cogmap/study/dvbf_*.py"],
        "libraries": ["genmodel/latent_map.py", "genmodel/charts.py", "genmodel/dvbf.py", "genmodel/dvbf_scan.py",
                      "genmodel/occupancy_lidar.py", "inference/particle_filter.py", "inference/particle_scheme.py",
                      "inference/chunked_filter.py", "inference/elbo.py", "inference/online_slam.py",
                      "inference/offline_slam.py", "inference/grid_mcl.py", "inference/pose_search.py",
                      "inference/goal_encoding.py", "inference/dvbf_files.py", "inference/se2.py",
                      "planning/knn_entropy.py", "planning/mi_exploration.py", "planning/mi_planner.py",
                      "planning/frontier_pull.py", "planning/maze_explorers.py", "planning/hybrid_astar.py",
                      "envs/maze*.py"],
    },
    "drone": {
        "agent": ["cogmap/drone/*.py"],
        "studies": ["cogmap/study/drone.py"],
        "libraries": ["genmodel/suitability.py", "genmodel/drone_beliefs.py", "genmodel/voxel_map.py",
                      "inference/kernel_filter.py", "planning/drone_*.py", "envs/drone_*.py"],
    },
}


def lines(patterns: list[str]) -> int:
    files = sorted({p for pat in patterns for p in ROOT.glob(pat)})
    return sum(len(f.read_text().splitlines()) for f in files)


def main() -> None:
    print(f"{'system':<10} {'agent':>7} {'+studies':>9} {'libraries':>10} {'share':>7} {'share with studies':>19}")
    for name, parts in SYSTEMS.items():
        a, s, lib = lines(parts["agent"]), lines(parts["studies"]), lines(parts["libraries"])
        print(f"{name:<10} {a:>7} {a + s:>9} {lib:>10} {100 * a / (a + lib):>6.1f}% "
              f"{100 * (a + s) / (a + s + lib):>18.1f}%")


if __name__ == "__main__":
    main()
