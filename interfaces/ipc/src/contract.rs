//! The run-time contract for clients in any language, generated from the code: every
//! service's settings that iceoryx2 checks when a second process opens it, the wake event
//! ids, and — with the message layouts, enums and constants of `wingman-interfaces` — the
//! same contract as JSON for code generators (`docs/contract.json`), as a C header
//! (`clients/c/wingman.h`) and as Python `ctypes` (`clients/python/wingman_client/contract.py`). A test keeps `docs/INTERFACES.md`'s services part, the JSON
//! and the header equal to this output, and compiles the header.

use core::fmt::Write;

use serde_json::{Value, json};
use wingman_interfaces::Service;
use wingman_interfaces::doc::{self, EnumType, WireType};
use wingman_interfaces::layout::{Element, FieldInfo, Scalar};

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

/// A service's settings as a client that creates it must give them.
enum Settings {
    PubSub {
        payload: &'static str,
        history: usize,
        buffer: usize,
        publishers: usize,
        subscribers: usize,
        nodes: usize,
    },
    Event {
        notifiers: usize,
        listeners: usize,
        nodes: usize,
    },
}

fn settings(s: Service) -> Settings {
    let q = qos(s);
    match doc::payload(s) {
        Some(payload) => Settings::PubSub {
            payload,
            history: q.history_size,
            buffer: q.subscriber_buffer,
            publishers: q.max_publishers,
            subscribers: q.max_subscribers,
            nodes: q.max_nodes,
        },
        None => Settings::Event {
            notifiers: q.max_publishers,
            listeners: q.max_subscribers,
            nodes: q.max_nodes,
        },
    }
}

/// The wire types in the order a declaration needs them: the structs inside messages,
/// then the messages.
fn declaration_order() -> impl Iterator<Item = WireType> {
    doc::structs().into_iter().chain(doc::messages())
}

/// Every enum value as a constant: (`MODEL_TWO_D`, 2).
fn enum_constants() -> Vec<(String, u32)> {
    doc::enums()
        .iter()
        .flat_map(|e| {
            e.variants.iter().map(|(name, value, _)| {
                (
                    format!("{}_{}", upper_snake(e.name), upper_snake(name)),
                    *value,
                )
            })
        })
        .collect()
}

/// A scalar's type in C and in Python `ctypes`.
fn scalar_types(s: Scalar) -> (&'static str, &'static str) {
    match s {
        Scalar::F64 => ("double", "ctypes.c_double"),
        Scalar::I64 => ("int64_t", "ctypes.c_int64"),
        Scalar::U64 => ("uint64_t", "ctypes.c_uint64"),
        Scalar::U32 => ("uint32_t", "ctypes.c_uint32"),
        Scalar::U8 => ("uint8_t", "ctypes.c_uint8"),
    }
}

/// The services' settings and the wake event ids, as `docs/INTERFACES.md` shows them.
pub fn services_markdown() -> String {
    let mut out = String::new();
    out.push_str(
        "## Service settings\n\n\
         Either process may create a service; the other opens it. iceoryx2 refuses the \
         open when the payload type differs (its type name, the `iceoryx2 type name` of \
         the tables above, its size, an alignment over the creator's), when the user header \
         is not none (`()`, size 0, alignment 1), when safe overflow differs, or when the \
         service holds less than the opener asks for (history, subscriber buffer, \
         publishers or notifiers, subscribers or listeners, nodes). So a client that \
         creates a service gives it these settings, and one that opens a service asks for \
         no more than these. The planner's subscribers ask for the whole history and use \
         the buffer size; its publishers loan one sample at a time. An event service \
         created by a client must allow event ids up to 3 (`event_id_max_value`; \
         iceoryx2's default allows more).\n\n",
    );
    out.push_str(
        "| service | name | kind | history | subscriber buffer | max publishers / notifiers | \
         max subscribers / listeners | max nodes | safe overflow |\n\
         |---|---|---|---:|---:|---:|---:|---:|---|\n",
    );
    for s in Service::ALL {
        let row = match settings(s) {
            Settings::PubSub {
                payload,
                history,
                buffer,
                publishers,
                subscribers,
                nodes,
            } => format!(
                "publish-subscribe `{payload}` | {history} | {buffer} | {publishers} | \
                 {subscribers} | {nodes} | yes"
            ),
            Settings::Event {
                notifiers,
                listeners,
                nodes,
            } => format!("event | - | - | {notifiers} | {listeners} | {nodes} | -"),
        };
        let _ = writeln!(
            out,
            "| `{s:?}` | `wingman/<vehicle-id>/{}` | {row} |",
            s.suffix()
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
            let name = format!("wingman/<vehicle-id>/{}", s.suffix());
            match settings(*s) {
                Settings::PubSub {
                    payload,
                    history,
                    buffer,
                    publishers,
                    subscribers,
                    nodes,
                } => json!({
                    "service": format!("{s:?}"),
                    "name": name,
                    "kind": "publish_subscribe",
                    "payload": payload,
                    "history_size": history,
                    "subscriber_max_buffer_size": buffer,
                    "max_publishers": publishers,
                    "max_subscribers": subscribers,
                    "max_nodes": nodes,
                    "enable_safe_overflow": true,
                }),
                Settings::Event {
                    notifiers,
                    listeners,
                    nodes,
                } => json!({
                    "service": format!("{s:?}"),
                    "name": name,
                    "kind": "event",
                    "max_notifiers": notifiers,
                    "max_listeners": listeners,
                    "max_nodes": nodes,
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

/// `Model::TwoD` → `TWO_D`: a variant's name as a C constant's suffix.
fn upper_snake(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out
}

fn c_scalar(element: Element) -> String {
    match element {
        Element::Scalar(s) => scalar_types(s).0.to_string(),
        Element::Struct { name, .. } => format!("wingman_{name}"),
    }
}

fn c_struct(out: &mut String, t: &WireType) {
    let name = format!("wingman_{}", t.name);
    let _ = writeln!(out, "/* {} */", one_line(t.doc));
    let _ = writeln!(out, "typedef struct {name} {{");
    for f in t.fields {
        let dims: String = (f.dims)().iter().map(|d| format!("[{d}]")).collect();
        let unit = if f.unit == "-" {
            String::new()
        } else {
            format!(" [{}]", f.unit)
        };
        let _ = writeln!(
            out,
            "    {} {}{dims}; /* {}{unit} */",
            c_scalar(f.element),
            f.name,
            one_line(f.doc).replace("*/", "* /")
        );
    }
    // iceoryx2-cxx takes a payload's type name from `IOX2_TYPE_NAME`: the Rust side's.
    let _ = writeln!(
        out,
        "#ifdef __cplusplus\n    static constexpr const char *IOX2_TYPE_NAME = \"{}\";\n#endif",
        t.type_name
    );
    let _ = writeln!(out, "}} {name};");
    let _ = writeln!(
        out,
        "#define WINGMAN_{}_TYPE_NAME \"{}\"",
        upper_snake(t.name),
        t.type_name
    );
    let _ = writeln!(
        out,
        "WINGMAN_STATIC_ASSERT(sizeof({name}) == {}, \"size of {name}\");",
        t.size
    );
    let _ = writeln!(
        out,
        "WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF({name}) == {}, \"alignment of {name}\");",
        t.align
    );
    for f in t.fields {
        let _ = writeln!(
            out,
            "WINGMAN_STATIC_ASSERT(offsetof({name}, {}) == {}, \"offset of {name}.{}\");",
            f.name, f.offset, f.name
        );
    }
    out.push('\n');
}

/// The C header of the contract (`clients/c/wingman.h`): constants, wake ids, enum values,
/// service name suffixes and every wire struct, with a static assertion of every size,
/// alignment and offset. C11 or C++11.
pub fn c_header() -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "/* wingman.h: the wingman planner's message contract for C and C++ (protocol {}).\n\
         \x20* Generated from the Rust code (`WINGMAN_BLESS=1 cargo test -p wingman-ipc --test\n\
         \x20* contract`); do not edit. Layouts are little-endian, `#[repr(C)]`, with no implicit\n\
         \x20* padding; docs/INTERFACES.md says what each field means. */\n\
         #ifndef WINGMAN_H\n#define WINGMAN_H\n\n\
         #include <stddef.h>\n#include <stdint.h>\n\n\
         #ifdef __cplusplus\n\
         #define WINGMAN_STATIC_ASSERT(c, m) static_assert(c, m)\n\
         #define WINGMAN_ALIGNOF(t) alignof(t)\n\
         #else\n\
         #define WINGMAN_STATIC_ASSERT(c, m) _Static_assert(c, m)\n\
         #define WINGMAN_ALIGNOF(t) _Alignof(t)\n\
         #endif\n\n",
        wingman_interfaces::PROTOCOL_VERSION
    );
    out.push_str("/* Constants */\n");
    for (name, value) in doc::constants() {
        let _ = writeln!(out, "#define WINGMAN_{name} {value}");
    }
    out.push_str("\n/* Wake event ids */\n");
    for (name, id, meaning) in wake_events() {
        let meaning = meaning.replace('`', "");
        let _ = writeln!(out, "#define WINGMAN_{name} {id} /* {meaning} */");
    }
    out.push_str("\n/* Service names: \"wingman/\" <vehicle id> \"/\" suffix */\n");
    for s in Service::ALL {
        let _ = writeln!(
            out,
            "#define WINGMAN_SERVICE_{} \"{}\"",
            upper_snake(&format!("{s:?}")),
            s.suffix()
        );
    }
    out.push_str("\n/* Enum values (u32 fields) */\n");
    for (name, value) in enum_constants() {
        let _ = writeln!(out, "#define WINGMAN_{name} {value}");
    }
    let structs = doc::structs().len();
    for (k, t) in declaration_order().enumerate() {
        match k {
            0 => out.push_str("\n/* Structs inside messages */\n\n"),
            k if k == structs => out.push_str("/* Messages */\n\n"),
            _ => {}
        }
        c_struct(&mut out, &t);
    }
    out.push_str("#endif /* WINGMAN_H */\n");
    out
}

fn py_type(f: &FieldInfo) -> String {
    let base = match f.element {
        Element::Scalar(s) => scalar_types(s).1.to_string(),
        Element::Struct { name, .. } => name.to_string(),
    };
    // C order: the last dimension is the innermost array.
    (f.dims)()
        .iter()
        .rev()
        .fold(base, |inner, d| format!("({inner} * {d})"))
}

fn py_struct(out: &mut String, t: &WireType) {
    let _ = writeln!(out, "\nclass {}(ctypes.Structure):", t.name);
    let _ = writeln!(
        out,
        "    \"\"\"{}\"\"\"\n",
        one_line(t.doc).replace('\\', "\\\\")
    );
    out.push_str("    _fields_ = [\n");
    for f in t.fields {
        let _ = writeln!(out, "        (\"{}\", {}),", f.name, py_type(f));
    }
    out.push_str("    ]\n\n");
    let _ = writeln!(out, "    SIZE = {}", t.size);
    let _ = writeln!(out, "    ALIGN = {}", t.align);
    out.push_str("\n    @staticmethod\n    def type_name() -> str:\n");
    let _ = writeln!(out, "        return \"{}\"", t.type_name);
}

/// The Python module of the contract (`clients/python/wingman_client/contract.py`): the
/// constants, wake ids, service suffixes and settings, enum values, and every wire struct
/// as a `ctypes.Structure` with the iceoryx2 type name the Rust side gives it.
pub fn python_module() -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "\"\"\"The wingman planner's message contract (protocol {}), as Python ctypes.\n\n\
         Generated from the Rust code (`WINGMAN_BLESS=1 cargo test -p wingman-ipc --test contract`);\n\
         do not edit. Layouts are little-endian and `repr(C)` with no implicit padding;\n\
         docs/INTERFACES.md says what each field means.\n\
         \"\"\"\n\n\
         import ctypes\n\n",
        wingman_interfaces::PROTOCOL_VERSION
    );
    for (name, value) in doc::constants() {
        let _ = writeln!(out, "{name} = {value}");
    }
    out.push('\n');
    for (name, id, meaning) in wake_events() {
        let _ = writeln!(out, "{name} = {id}  # {}", meaning.replace('`', ""));
    }
    out.push_str(
        "\n# Service name suffixes: \"wingman/\" + vehicle id + \"/\" + suffix.\nSERVICES = {\n",
    );
    for s in Service::ALL {
        let _ = writeln!(out, "    \"{s:?}\": \"{}\",", s.suffix());
    }
    out.push_str(
        "}\n\n# The settings iceoryx2 compares when a second process opens a service.\nSETTINGS = {\n",
    );
    for s in Service::ALL {
        let _ = match settings(s) {
            Settings::PubSub {
                history,
                buffer,
                publishers,
                subscribers,
                nodes,
                ..
            } => writeln!(
                out,
                "    \"{s:?}\": {{\"history_size\": {history}, \"subscriber_max_buffer_size\": \
                 {buffer}, \"max_publishers\": {publishers}, \"max_subscribers\": {subscribers}, \
                 \"max_nodes\": {nodes}}},"
            ),
            Settings::Event {
                notifiers,
                listeners,
                nodes,
            } => writeln!(
                out,
                "    \"{s:?}\": {{\"max_notifiers\": {notifiers}, \"max_listeners\": {listeners}, \
                 \"max_nodes\": {nodes}}},"
            ),
        };
    }
    out.push_str("}\n");
    for e in doc::enums() {
        let _ = writeln!(out, "\n# {}: {}", e.name, one_line(e.doc));
        for (name, value, _) in e.variants {
            let _ = writeln!(
                out,
                "{}_{} = {value}",
                upper_snake(e.name),
                upper_snake(name)
            );
        }
    }
    out.push('\n');
    for t in declaration_order() {
        py_struct(&mut out, &t);
        out.push('\n');
    }
    out.push_str("\nMESSAGES = {\n");
    for s in Service::ALL {
        if let Some(p) = doc::payload(s) {
            let _ = writeln!(out, "    \"{s:?}\": {p},");
        }
    }
    out.push_str("}\n");
    out
}
