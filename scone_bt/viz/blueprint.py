"""The default viewer layout: scene and camera left, the tree and the gate in the middle, plots right."""

from __future__ import annotations

from typing import TYPE_CHECKING

from scone_bt.viz import paths as P

if TYPE_CHECKING:
    import rerun.blueprint as rrb

__all__ = ["default_blueprint"]


def default_blueprint() -> rrb.Blueprint:
    """A layout in which every panel of a SCONE-BT recording is visible without dragging anything."""
    import rerun.blueprint as rrb

    scene = rrb.Spatial3DView(
        origin=P.WORLD,
        contents=["$origin/**", f"- /{P.DEPTH}"],  # the depth image would cover the RGB one in the frustum
        name="Kitchen",
        eye_controls=rrb.EyeControls3D(
            position=(1.5, -1.0, 0.85), look_target=(0.3, 0.0, 0.0), eye_up=(0, 0, 1)
        ),
    )
    camera = rrb.Horizontal(
        rrb.Spatial2DView(
            origin=P.IMAGE, contents=[f"{P.RGB}", f"{P.DETECTIONS_2D}"], name="Camera RGB + detections"
        ),
        rrb.Spatial2DView(origin=P.IMAGE, contents=[f"{P.DEPTH}"], name="Depth"),
    )
    left = rrb.Vertical(scene, camera, row_shares=[3, 2])

    tree = rrb.Tabs(
        rrb.GraphView(origin=P.TREE_GRAPH, name="Behaviour tree"),
        rrb.TextDocumentView(origin=P.TREE_TEXT, name="Tree (text)"),
        rrb.StateTimelineView(origin=P.TREE_STATUS, name="Node status over time"),
    )
    gate = rrb.Tabs(
        rrb.TextDocumentView(origin=P.AFFORDANCE_TABLE, name="Affordances"),
        rrb.BarChartView(origin=P.AFFORDANCE_RELEVANCE, name="Relevance (ranked)"),
        rrb.BarChartView(origin=P.AFFORDANCE_CONFIDENCE, name="Confidence (ranked)"),
    )
    middle = rrb.Vertical(
        tree,
        rrb.Horizontal(
            rrb.TextDocumentView(origin=P.GATE_DECISION, name="Decision"),
            rrb.TextDocumentView(origin=P.RECIPE, name="Recipe"),
        ),
        gate,
        row_shares=[3, 2, 2],
    )

    plots = rrb.Vertical(
        rrb.Horizontal(
            rrb.TimeSeriesView(
                origin=P.CONFIDENCE,
                name="Self-confidence κ̂ per object",
                axis_y=rrb.ScalarAxis(range=(0.0, 1.0)),
            ),
            rrb.TimeSeriesView(
                origin=P.PERSON_TRUST,
                name="Person's trust per object (estimated)",
                axis_y=rrb.ScalarAxis(range=(0.0, 1.0)),
            ),
        ),
        rrb.TimeSeriesView(origin=P.COUNTERS, name="Outcomes"),
        rrb.Tabs(
            rrb.TimeSeriesView(
                origin=P.TRAJECTORY,
                contents=[P.PLANNED_POSITION, P.EXECUTED_POSITION],
                name="Joints: planned vs executed (rad)",
                plot_legend=rrb.PlotLegend(visible=False),  # 14 series: the legend would hide the plot
            ),
            rrb.TimeSeriesView(
                origin=P.PLANNED_VELOCITY,
                name="Joint velocities (rad/s)",
                plot_legend=rrb.PlotLegend(visible=False),
            ),
            rrb.StateTimelineView(origin=P.GATE_KIND, name="Gate: act / ask"),
            rrb.TimeSeriesView(origin=P.EPISODE_SIM_TIME, name="Simulated time (flat: planning)"),
        ),
        rrb.TextLogView(origin=P.LOG, name="Log"),
        row_shares=[2, 1.4, 2, 1.6],
    )
    return rrb.Blueprint(
        rrb.Horizontal(left, middle, plots, column_shares=[2.2, 1.6, 1.6]),
        rrb.TimePanel(timeline=P.SIM_TIME, state="expanded"),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
    )
