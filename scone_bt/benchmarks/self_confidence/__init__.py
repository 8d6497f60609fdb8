"""The self-confidence benchmark: proficiency-profile datasets from the simulator and the paper's Algorithm 1.

    profiles = load_profiles("tools/profiles")               # robots of different proficiency
    datasets = load_eval_datasets("tools/data/sc", min_rows=100)  # one outcome table per robot
    X = embed_datasets(datasets, load_embedder("minilm").embed)
    result = evaluate_protocols("minilm", "knn", datasets, X, lambda s: make_estimator("knn", seed=s))

`scone-bench sc generate` runs the real perception and pick-and-place in PyBullet; `scone-bench sc evaluate`
(evaluate.py; protocols in protocols.py) writes every protocol's numbers as JSON, Markdown and PNGs.
"""

from scone_bt.benchmarks.self_confidence.dataset import (
    COLUMNS,
    Dataset,
    ExecutionRecord,
    load_datasets,
    read_dataset,
    read_records,
    write_records,
)
from scone_bt.benchmarks.self_confidence.evaldata import EvalDataset, load_eval_datasets
from scone_bt.benchmarks.self_confidence.evaluate import (
    Estimator,
    EstimatorFactory,
    EvalOptions,
    PairResult,
    embed_datasets,
    evaluate_pair,
    prior_baseline,
    shuffled_order,
)
from scone_bt.benchmarks.self_confidence.metrics import (
    accuracy,
    auroc,
    brier_score,
    expected_calibration_error,
    normalised_auc,
    reliability_bins,
)
from scone_bt.benchmarks.self_confidence.profiles import (
    INJECTABLE_STAGES,
    InjectedFailure,
    Profile,
    load_profile,
    load_profiles,
)
from scone_bt.benchmarks.self_confidence.protocols import Protocol, evaluate_protocols
from scone_bt.benchmarks.self_confidence.report import (
    dataset_summary,
    evaluation_markdown,
    plot_curves,
    plot_reliability,
    write_json,
)

__all__ = [
    "COLUMNS",
    "INJECTABLE_STAGES",
    "Dataset",
    "Estimator",
    "EvalDataset",
    "EstimatorFactory",
    "EvalOptions",
    "ExecutionRecord",
    "InjectedFailure",
    "PairResult",
    "Profile",
    "Protocol",
    "accuracy",
    "auroc",
    "brier_score",
    "dataset_summary",
    "embed_datasets",
    "evaluate_pair",
    "evaluate_protocols",
    "evaluation_markdown",
    "expected_calibration_error",
    "load_datasets",
    "load_eval_datasets",
    "load_profile",
    "load_profiles",
    "normalised_auc",
    "plot_curves",
    "plot_reliability",
    "prior_baseline",
    "read_dataset",
    "read_records",
    "reliability_bins",
    "shuffled_order",
    "write_json",
    "write_records",
]
