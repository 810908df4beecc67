//! The run-time contract for clients in any language, generated from the code: every
//! service's settings that iceoryx2 checks when a second process opens it, the wake event
//! ids, and — with the message layouts, enums and constants of `wingman-interfaces` — the
//! same contract as JSON for code generators (`docs/contract.json`). A test keeps
//! `docs/INTERFACES.md`'s services part and `docs/contract.json` equal to this output.

use core::fmt::Write;

use serde_json::{Value, json};
use wingman_interfaces::Service;
use wingman_interfaces::doc::{self, EnumType, WireType};
use wingman_interfaces::layout::{Element, FieldInfo};

use crate::{WAKE_HARNESS, WAKE_INPUT, WAKE_SOLVER, qos};

/// The wake event ids: (name, id, who notifies which service, when).
pub fn wake_events() -> [(&'static str, usize, &'static str); 3] {
    [
        (
            "WAKE_INPUT",
            WAKE_INPUT.as_value(),
            "a client (the harness) notifies `wake/planner` after publishing inputs",
        ),
        (
            "WAKE_SOLVER",
            WAKE_SOLVER.as_value(),
            "the planner's solve thread notifies `wake/planner` after a plan (internal)",
        ),
        (
            "WAKE_HARNESS",
            WAKE_HARNESS.as_value(),
            "the planner notifies `wake/harness` after each plan or status",
        ),
    ]
}

/// The services' settings and the wake event ids, as `docs/INTERFACES.md` shows them.
pub fn services_markdown() -> String {
    let mut out = String::new();
    out.push_str(
        "## Service settings\n\n\
         Either process may create a service; the other opens it, and iceoryx2 refuses the \
         open when a setting below differs. A client that creates a service must give it \
         exactly these settings (publish-subscribe: safe overflow on, the history, the \
         subscriber buffer, the publisher, subscriber and node counts; event: the \
         notifier, listener and node counts). Its subscribers ask for the whole history \
         and use the buffer size; its publishers loan one sample at a time.\n\n",
    );
    out.push_str(
        "| service | name | kind | history | subscriber buffer | max publishers / notifiers | \
         max subscribers / listeners | max nodes | safe overflow |\n\
         |---|---|---|---:|---:|---:|---:|---:|---|\n",
    );
    for s in Service::ALL {
        let q = qos(s);
        let (kind, history, buffer, overflow) = match doc::payload(s) {
            Some(p) => (
                format!("publish-subscribe `{p}`"),
                q.history_size.to_string(),
                q.subscriber_buffer.to_string(),
                "yes",
            ),
            None => ("event".to_string(), "-".into(), "-".into(), "-"),
        };
        let _ = writeln!(
            out,
            "| `{s:?}` | `wingman/<vehicle-id>/{}` | {kind} | {history} | {buffer} | {} | {} | {} | {overflow} |",
            s.suffix(),
            q.max_publishers,
            q.max_subscribers,
            q.max_nodes
        );
    }
    out.push_str("\n## Wake event ids\n\n| name | id | use |\n|---|---:|---|\n");
    for (name, id, meaning) in wake_events() {
        let _ = writeln!(out, "| `{name}` | {id} | {meaning} |");
    }
    out.push_str(
        "\nThe planner wakes on any id of `wake/planner`; a client should notify with \
         `WAKE_INPUT`.\n",
    );
    out
}

fn field_json(f: &FieldInfo) -> Value {
    let (element, scalar) = match f.element {
        Element::Scalar(s) => (s.name(), true),
        Element::Struct { name, .. } => (name, false),
    };
    json!({
        "name": f.name,
        "offset": f.offset,
        "size": f.size,
        "c_type": f.c_type(),
        "element": element,
        "element_is_struct": !scalar,
        "count": f.count,
        "dims": (f.dims)(),
        "unit": f.unit,
        "doc": one_line(f.doc),
    })
}

fn wire_json(t: &WireType) -> Value {
    json!({
        "name": t.name,
        "type_name": t.type_name,
        "doc": one_line(t.doc),
        "size": t.size,
        "align": t.align,
        "fields": t.fields.iter().map(field_json).collect::<Vec<_>>(),
    })
}

fn enum_json(e: &EnumType) -> Value {
    json!({
        "name": e.name,
        "doc": one_line(e.doc),
        "variants": e.variants.iter().map(|(name, value, doc)| json!({
            "name": name,
            "value": value,
            "doc": one_line(doc),
        })).collect::<Vec<_>>(),
    })
}

fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The whole contract as JSON (`docs/contract.json`): constants, services with their
/// settings, wake event ids, messages, the structs inside them and the enums. Offsets
/// and sizes are bytes; every struct is `#[repr(C)]`, little-endian on the supported
/// hosts.
pub fn contract_json() -> Value {
    let constants: serde_json::Map<String, Value> = doc::constants()
        .into_iter()
        .map(|(name, value)| (name.to_string(), json!(value)))
        .collect();
    let services: Vec<Value> = Service::ALL
        .iter()
        .map(|s| {
            let q = qos(*s);
            let name = format!("wingman/<vehicle-id>/{}", s.suffix());
            match doc::payload(*s) {
                Some(payload) => json!({
                    "service": format!("{s:?}"),
                    "name": name,
                    "kind": "publish_subscribe",
                    "payload": payload,
                    "history_size": q.history_size,
                    "subscriber_max_buffer_size": q.subscriber_buffer,
                    "max_publishers": q.max_publishers,
                    "max_subscribers": q.max_subscribers,
                    "max_nodes": q.max_nodes,
                    "enable_safe_overflow": true,
                }),
                None => json!({
                    "service": format!("{s:?}"),
                    "name": name,
                    "kind": "event",
                    "max_notifiers": q.max_publishers,
                    "max_listeners": q.max_subscribers,
                    "max_nodes": q.max_nodes,
                }),
            }
        })
        .collect();
    let events: Vec<Value> = wake_events()
        .iter()
        .map(|(name, id, meaning)| json!({ "name": name, "id": id, "use": meaning }))
        .collect();
    json!({
        "protocol_version": wingman_interfaces::PROTOCOL_VERSION,
        "byte_order": "little-endian",
        "constants": constants,
        "services": services,
        "wake_events": events,
        "messages": doc::messages().iter().map(wire_json).collect::<Vec<_>>(),
        "structs": doc::structs().iter().map(wire_json).collect::<Vec<_>>(),
        "enums": doc::enums().iter().map(enum_json).collect::<Vec<_>>(),
    })
}
