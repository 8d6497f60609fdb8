"""The self-confidence benchmark: proficiency-profile datasets from the simulator and the paper's Algorithm 1.

    profiles = load_profiles("tools/profiles")               # robots of different proficiency
    datasets = load_datasets("tools/data/sc", min_rows=100)  # one outcome table per robot
    X = embed_datasets(datasets, load_embedder("minilm").embed)
    result = evaluate_pair("minilm", "knn", datasets, X, lambda s: make_estimator("knn", seed=s))

The generator (tools/gen_sc_datasets.py) runs the real perception and pick-and-place in PyBullet; the evaluator
(tools/eval_sc.py) writes the Table I layout, a JSON of every number and the learning-curve plot.
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
)
from scone_bt.benchmarks.self_confidence.profiles import (
    INJECTABLE_STAGES,
    InjectedFailure,
    Profile,
    load_profile,
    load_profiles,
)
from scone_bt.benchmarks.self_confidence.report import (
    dataset_summary,
    markdown_tables,
    outcome_structure,
    plot_learning_curves,
    write_json,
)

__all__ = [
    "COLUMNS",
    "INJECTABLE_STAGES",
    "Dataset",
    "Estimator",
    "EstimatorFactory",
    "EvalOptions",
    "ExecutionRecord",
    "InjectedFailure",
    "PairResult",
    "Profile",
    "accuracy",
    "auroc",
    "brier_score",
    "dataset_summary",
    "embed_datasets",
    "evaluate_pair",
    "expected_calibration_error",
    "load_datasets",
    "load_profile",
    "load_profiles",
    "markdown_tables",
    "normalised_auc",
    "outcome_structure",
    "plot_learning_curves",
    "prior_baseline",
    "read_dataset",
    "read_records",
    "shuffled_order",
    "write_json",
    "write_records",
]
