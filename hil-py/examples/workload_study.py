# %% [markdown]
# # From a workload study to a feeding policy that weighs workload
#
# 1. load a querying-workload study (the CSV that `hil study` exports),
# 2. select a workload model by cross-validation and fit it,
# 3. run LinUCB-QG in the Gymnasium feeding environment, its queries
#    scored and forecast by that model,
# 4. plot the workload the episodes put on the person.
#
# Everything bundled with hil is **synthetic**, calibrated to published
# figures: the study, the food data and so every number below are not the
# paper's. Run it as a script (`python hil-py/examples/workload_study.py
# --help`) or cell by cell in an editor that knows `# %%` cells.

# %%
from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # writes files; no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hil  # noqa: E402
from hil.envs import FoodReplayEnv  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
STUDY = REPO / "hil-workload" / "data" / "synthetic_study.csv"


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description="workload study -> model -> LinUCB-QG -> plot")
    ap.add_argument("--study", type=Path, default=STUDY, help="study CSV (hil's study format)")
    ap.add_argument("--population", default="d12", help="dataset to select on: d1, d2 or d12")
    ap.add_argument("--histories", default="1,5,10,15,20,25,30",
                    help="Granger history lengths H to cross-validate (comma-separated)")
    ap.add_argument("--episodes", type=int, default=5, help="episodes (seeds 0..n-1)")
    ap.add_argument("--items", type=int, default=5, help="items per episode (a plate)")
    ap.add_argument("--w", type=float, default=4.0, help="LinUCB-QG's workload weight w")
    ap.add_argument("--out", type=Path, default=Path("workload_rollout.png"))
    return ap.parse_args(argv)


def main(argv=None) -> dict:
    args = parse_args(argv)

    # %% 1-2. Select a workload model on the study and fit it on all of it.
    histories = [int(h) for h in args.histories.split(",") if h]
    study = hil.Study.load(args.study)
    table = hil.select_workload(study, histories=histories)
    rows = [r for r in table["rows"] if r["dataset"] == args.population]
    best = min(rows, key=lambda r: r["median"])
    cand = best["candidate"]
    print(f"selected on {args.population.upper()}: {cand} (median test MSE {best['median']:.4f})")
    model_file = Path(tempfile.mkdtemp()) / "workload_model.json"
    model = hil.fit_workload(study, population=args.population, model=cand, out=model_file)

    # %% 3. LinUCB-QG in the Gymnasium environment, with that model.
    env = FoodReplayEnv(
        items_per_episode=args.items,
        workload={"type": "model_file", "path": str(model_file)},
    )
    qg = env.policy({"type": "linucb_qg", "alpha": 0.5, "w": args.w, "pretrain": True})
    curves, metrics = [], []
    for seed in range(args.episodes):
        obs, info = env.reset(seed=seed)
        ts, wls, asks = [0], [env.wl0], []
        done = False
        while not done:
            t = info["t"]
            action = env.act(qg)
            obs, reward, done, _, info = env.step(action)
            env.learn(qg)  # it keeps learning across episodes
            # The workload trace after the step's last attempt.
            ts.append(t + len(info["executed_arms"]) - 1)
            wls.append(info["wl_t"])
            if action == env.ask_action:
                asks.append((t, info["wl_t"]))
        curves.append((ts, wls, asks))
        metrics.append(info["episode"])

    r_task = np.array([m["r_task_avg"] for m in metrics])
    d_wl = np.array([m["delta_wl"] for m in metrics])
    se = lambda x: x.std(ddof=1) / np.sqrt(len(x)) if len(x) > 1 else float("nan")  # noqa: E731
    print(
        f"LinUCB-QG (w = {args.w}) over {len(metrics)} episodes (seeds 0..{len(metrics) - 1}): "
        f"r_task = {r_task.mean():.3f} +- {se(r_task):.3f} (SE), "
        f"dWL = {d_wl.mean():.3f} +- {se(d_wl):.3f} (SE), "
        f"queries per episode = {np.mean([m['n_q'] for m in metrics]):.2f}"
    )

    # %% 4. Plot the workload rollout of every episode.
    fig, ax = plt.subplots(figsize=(7, 4))
    for k, (ts, wls, asks) in enumerate(curves):
        line, = ax.step(ts, wls, where="post", label=f"seed {k}")
        if asks:  # a marker where the policy asked
            ax.plot(*zip(*asks), "v", color=line.get_color())
    ax.set_xlabel("timestep t (10 s)")
    ax.set_ylabel("workload WL_t")
    ax.set_ylim(0, 1)
    ax.set_title(f"LinUCB-QG under {model.name} (selected and fitted on {args.population.upper()})"
                 "\nsynthetic data, not the paper's", fontsize="medium")
    ax.legend(fontsize="small", ncol=2)
    fig.tight_layout()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=100)
    plt.close(fig)
    print(f"wrote {os.fspath(args.out)}")
    return {"model": cand, "metrics": metrics, "plot": str(args.out)}


if __name__ == "__main__":
    main()
