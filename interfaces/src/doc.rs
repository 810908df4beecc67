//! The generated part of `docs/INTERFACES.md`: one table per wire type, one per enum, the
//! capacities and the service names. A test compares the document with this output.

use crate::layout::{Element, FieldInfo, Wire, WireEnum};
use crate::*;
use core::fmt::Write;
use core::mem::{align_of, size_of};

fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// One wire type of the contract: what the document and code generators say of it.
#[derive(Clone, Copy)]
pub struct WireType {
    pub name: &'static str,
    /// Its iceoryx2 type name.
    pub type_name: &'static str,
    pub doc: &'static str,
    pub size: usize,
    pub align: usize,
    pub fields: &'static [FieldInfo],
}

fn wire<T: Wire>() -> WireType {
    WireType {
        name: T::NAME,
        type_name: T::TYPE_NAME,
        doc: T::DOC,
        size: size_of::<T>(),
        align: align_of::<T>(),
        fields: T::fields(),
    }
}

/// One `u32`-coded enum of the contract.
#[derive(Clone, Copy)]
pub struct EnumType {
    pub name: &'static str,
    pub doc: &'static str,
    /// (name, wire value, meaning) of each variant.
    pub variants: &'static [(&'static str, u32, &'static str)],
}

fn wire_enum<E: WireEnum>() -> EnumType {
    EnumType {
        name: E::NAME,
        doc: E::DOC,
        variants: E::variants(),
    }
}

/// Every constant of the contract, by name.
pub fn constants() -> Vec<(&'static str, usize)> {
    vec![
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
    ]
}

/// The messages, one per publish-subscribe service.
pub fn messages() -> Vec<WireType> {
    vec![
        wire::<Tasking>(),
        wire::<LeadState>(),
        wire::<LeadRoute>(),
        wire::<ThreatReport>(),
        wire::<TrackFix>(),
        wire::<OwnshipState>(),
        wire::<Plan>(),
        wire::<PlannerStatus>(),
    ]
}

/// The structs inside messages.
pub fn structs() -> Vec<WireType> {
    vec![
        wire::<Header>(),
        wire::<VehicleLimits>(),
        wire::<Weights>(),
        wire::<PlanSample>(),
        wire::<PlanCut>(),
    ]
}

/// The enums.
pub fn enums() -> Vec<EnumType> {
    vec![
        wire_enum::<Model>(),
        wire_enum::<Objective>(),
        wire_enum::<ThreatKind>(),
        wire_enum::<Trigger>(),
        wire_enum::<Quality>(),
        wire_enum::<PlanPath>(),
        wire_enum::<PlannerState>(),
    ]
}

/// The message a service carries (`None`: an event service).
pub fn payload(service: Service) -> Option<&'static str> {
    match service {
        Service::Tasking => Some("Tasking"),
        Service::LeadRoute => Some("LeadRoute"),
        Service::LeadState => Some("LeadState"),
        Service::Threats => Some("ThreatReport"),
        Service::Tracks => Some("TrackFix"),
        Service::Ownship => Some("OwnshipState"),
        Service::Plan => Some("Plan"),
        Service::Status => Some("PlannerStatus"),
        Service::PlannerWake | Service::HarnessWake => None,
    }
}

fn wire_table(out: &mut String, t: &WireType) {
    let _ = writeln!(out, "### `{}`\n", t.name);
    let _ = writeln!(out, "{}\n", one_line(t.doc));
    let _ = writeln!(
        out,
        "Size {} bytes, alignment {}, iceoryx2 type name `{}`.\n",
        t.size, t.align, t.type_name
    );
    let _ = writeln!(out, "| offset | field | type | unit | meaning |");
    let _ = writeln!(out, "|---:|---|---|---|---|");
    for f in t.fields {
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

fn enum_table(out: &mut String, e: &EnumType) {
    let _ = writeln!(out, "### `{}` (u32)\n", e.name);
    let _ = writeln!(out, "{}\n", one_line(e.doc));
    let _ = writeln!(out, "| value | name | meaning |");
    let _ = writeln!(out, "|---:|---|---|");
    for (name, value, doc) in e.variants {
        let _ = writeln!(out, "| {value} | `{name}` | {} |", one_line(doc));
    }
    out.push('\n');
}

/// The generated tables of `docs/INTERFACES.md`, in Markdown.
pub fn interfaces_markdown() -> String {
    let mut out = String::new();
    out.push_str("## Constants\n\n| name | value |\n|---|---:|\n");
    for (name, value) in constants() {
        let _ = writeln!(out, "| `{name}` | {value} |");
    }
    out.push_str("\n## Services\n\n| service | name | payload |\n|---|---|---|\n");
    for s in Service::ALL {
        let payload = payload(s).map_or("event (no payload)".to_string(), |p| format!("`{p}`"));
        let _ = writeln!(
            out,
            "| `{s:?}` | `wingman/<vehicle-id>/{}` | {payload} |",
            s.suffix()
        );
    }
    out.push_str("\n## Messages\n\n");
    for t in messages() {
        wire_table(&mut out, &t);
    }
    out.push_str("## Structs inside messages\n\n");
    for t in structs() {
        wire_table(&mut out, &t);
    }
    out.push_str("## Enums\n\n");
    for e in enums() {
        enum_table(&mut out, &e);
    }
    out
}
