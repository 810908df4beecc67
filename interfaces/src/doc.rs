//! The generated part of `docs/INTERFACES.md`: one table per wire type, one per enum, the
//! capacities and the service names. A test compares the document with this output.

use crate::layout::{Element, FieldInfo, Wire, WireEnum};
use crate::*;
use core::fmt::Write;
use core::mem::{align_of, size_of};

fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn wire_table<T: Wire>(out: &mut String) {
    let _ = writeln!(out, "### `{}`\n", T::NAME);
    let _ = writeln!(out, "{}\n", one_line(T::DOC));
    let _ = writeln!(
        out,
        "Size {} bytes, alignment {}, iceoryx2 type name `{}`.\n",
        size_of::<T>(),
        align_of::<T>(),
        type_name_of::<T>()
    );
    let _ = writeln!(out, "| offset | field | type | unit | meaning |");
    let _ = writeln!(out, "|---:|---|---|---|---|");
    for f in T::fields() {
        row(out, f);
    }
    out.push('\n');
}

fn row(out: &mut String, f: &FieldInfo) {
    let ty = f.c_type();
    let ty = match f.element {
        Element::Struct { name, .. } => {
            ty.replacen(name, &format!("[`{name}`](#{})", name.to_lowercase()), 1)
        }
        Element::Scalar(_) => format!("`{ty}`"),
    };
    let _ = writeln!(
        out,
        "| {} | `{}` | {} | {} | {} |",
        f.offset,
        f.name,
        ty,
        f.unit,
        one_line(f.doc)
    );
}

fn type_name_of<T: Wire>() -> &'static str {
    T::TYPE_NAME
}

fn enum_table<E: WireEnum>(out: &mut String) {
    let _ = writeln!(out, "### `{}` (u32)\n", E::NAME);
    let _ = writeln!(out, "{}\n", one_line(E::DOC));
    let _ = writeln!(out, "| value | name | meaning |");
    let _ = writeln!(out, "|---:|---|---|");
    for (name, value, doc) in E::variants() {
        let _ = writeln!(out, "| {value} | `{name}` | {} |", one_line(doc));
    }
    out.push('\n');
}

/// The generated tables of `docs/INTERFACES.md`, in Markdown.
pub fn interfaces_markdown() -> String {
    let mut out = String::new();
    out.push_str("## Constants\n\n| name | value |\n|---|---:|\n");
    for (name, value) in [
        ("PROTOCOL_VERSION", PROTOCOL_VERSION as usize),
        ("MAX_TARGETS", MAX_TARGETS),
        ("MAX_PHASES", MAX_PHASES),
        ("MAX_ROUTE_POINTS", MAX_ROUTE_POINTS),
        ("MAX_ROAD_POINTS", MAX_ROAD_POINTS),
        ("MAX_PLAN_SAMPLES", MAX_PLAN_SAMPLES),
        ("MAX_PLAN_CUTS", MAX_PLAN_CUTS),
        ("STATE_DIM", STATE_DIM),
        ("CONTROL_DIM", CONTROL_DIM),
        ("THREAT_NAME_LEN", THREAT_NAME_LEN),
        ("SENDER_PLANNER", SENDER_PLANNER as usize),
        ("SENDER_HARNESS", SENDER_HARNESS as usize),
        ("OWNSHIP_HOLDING", OWNSHIP_HOLDING as usize),
        ("STALE_TASKING", STALE_TASKING as usize),
        ("STALE_LEAD", STALE_LEAD as usize),
        ("STALE_OWNSHIP", STALE_OWNSHIP as usize),
        ("STALE_TRACKS", STALE_TRACKS as usize),
    ] {
        let _ = writeln!(out, "| `{name}` | {value} |");
    }
    out.push_str("\n## Services\n\n| service | name | payload |\n|---|---|---|\n");
    for s in Service::ALL {
        let payload = match s {
            Service::Tasking => "`Tasking`",
            Service::LeadRoute => "`LeadRoute`",
            Service::LeadState => "`LeadState`",
            Service::Threats => "`ThreatReport`",
            Service::Tracks => "`TrackFix`",
            Service::Ownship => "`OwnshipState`",
            Service::Plan => "`Plan`",
            Service::Status => "`PlannerStatus`",
            Service::PlannerWake | Service::HarnessWake => "event (no payload)",
        };
        let _ = writeln!(
            out,
            "| `{s:?}` | `wingman/<vehicle-id>/{}` | {payload} |",
            s.suffix()
        );
    }
    out.push_str("\n## Messages\n\n");
    wire_table::<Tasking>(&mut out);
    wire_table::<LeadState>(&mut out);
    wire_table::<LeadRoute>(&mut out);
    wire_table::<ThreatReport>(&mut out);
    wire_table::<TrackFix>(&mut out);
    wire_table::<OwnshipState>(&mut out);
    wire_table::<Plan>(&mut out);
    wire_table::<PlannerStatus>(&mut out);
    out.push_str("## Structs inside messages\n\n");
    wire_table::<Header>(&mut out);
    wire_table::<VehicleLimits>(&mut out);
    wire_table::<Weights>(&mut out);
    wire_table::<PlanSample>(&mut out);
    wire_table::<PlanCut>(&mut out);
    out.push_str("## Enums\n\n");
    enum_table::<Model>(&mut out);
    enum_table::<Objective>(&mut out);
    enum_table::<ThreatKind>(&mut out);
    enum_table::<Trigger>(&mut out);
    enum_table::<Quality>(&mut out);
    enum_table::<PlanPath>(&mut out);
    enum_table::<PlannerState>(&mut out);
    out
}
