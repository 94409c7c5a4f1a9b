"""Where the repository, the build and the commands a study starts are."""
import os

# python/dynhet/study/paths.py: the repository is four levels up.
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
BUILD = os.environ.get("BUILD_DIR", os.path.join(ROOT, "build"))
SIM = os.path.join(BUILD, "bin", "sim_node")
RUN_SCENE = os.path.join(ROOT, "launch_scripts", "run_scene.sh")
STUDY_PY = os.path.join(ROOT, "launch_scripts", "study.py")  # what a Slurm task runs
ANALYSE_PY = os.path.join(ROOT, "launch_scripts", "analyse_study.py")
