//! Fails when src/lib.rs drifts from capi/include/sogmm/sogmm.h: every
//! `SOGMM_API` prototype of the header must appear in the extern block with
//! the same name, argument count, argument types and return type (C types
//! translated by the fixed table in `rust_type`), every numeric or string
//! `#define SOGMM_*` constant must appear with the same value, and the crate
//! must declare nothing the header lacks. Both files are parsed as text, so
//! the test needs no C compiler and no bindgen.
use std::collections::BTreeMap;

const HEADER: &str = include_str!("../../../../capi/include/sogmm/sogmm.h");
const LIB_RS: &str = include_str!("../src/lib.rs");

/// name -> (argument types, return type); `None` return = void.
type Protos = BTreeMap<String, (Vec<String>, Option<String>)>;

fn strip_c_comments(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find("/*") {
        out.push_str(&rest[..i]);
        rest = match rest[i..].find("*/") {
            Some(j) => &rest[i + j + 2..],
            None => "",
        };
    }
    out.push_str(rest);
    out.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// A C type (without the parameter name) as the Rust type the crate must use.
fn rust_type(c: &str) -> String {
    let spaced = c.replace('*', " * ");
    let toks: Vec<&str> = spaced.split_whitespace().collect();
    let mut base_const = false;
    let mut i = 0;
    if toks.first() == Some(&"const") {
        base_const = true;
        i = 1;
    }
    let base = match toks[i] {
        "void" => "c_void",
        "char" => "c_char",
        "float" => "f32",
        "double" => "f64",
        "int32_t" => "i32",
        "uint32_t" => "u32",
        "int64_t" => "i64",
        "uint64_t" => "u64",
        "uint16_t" => "u16",
        "uint8_t" => "u8",
        "size_t" => "usize",
        other => other, // sogmm_* typedefs keep their names
    };
    let mut ty = base.to_string();
    let mut pointee_const = base_const;
    let mut j = i + 1;
    while j < toks.len() {
        match toks[j] {
            "*" => {
                ty = format!("*{} {}", if pointee_const { "const" } else { "mut" }, ty);
                pointee_const = false;
            }
            "const" => pointee_const = true, // `T* const`: the next level's pointee
            t => panic!("unexpected token {t:?} in C type {c:?}"),
        }
        j += 1;
    }
    ty
}

/// Splits "const float* points" into the type and the name.
fn split_param(p: &str) -> String {
    let p = p.trim();
    let cut = p
        .rfind(|c: char| !(c.is_alphanumeric() || c == '_'))
        .expect("parameter without a type");
    p[..=cut].trim().to_string()
}

/// The header without comments and preprocessor lines (with their `\`
/// continuations): only C declarations remain.
fn c_declarations(header: &str) -> String {
    let mut out = String::new();
    let mut continued = false;
    for line in strip_c_comments(header).lines() {
        let directive = continued || line.trim_start().starts_with('#');
        continued = directive && line.trim_end().ends_with('\\');
        if !directive {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

fn header_protos(header: &str) -> Protos {
    let text = c_declarations(header);
    let mut protos = Protos::new();
    for stmt in text.split(';') {
        let Some(at) = stmt.find("SOGMM_API ") else { continue };
        let decl = stmt[at + "SOGMM_API ".len()..]
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        let open = decl.find('(').unwrap_or_else(|| panic!("no '(' in {decl:?}"));
        let close = decl.rfind(')').unwrap();
        let head = decl[..open].trim();
        let name_at = head.rfind(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap();
        let name = head[name_at + 1..].to_string();
        let ret = head[..=name_at].trim();
        let ret = if ret == "void" { None } else { Some(rust_type(ret)) };
        let args_text = decl[open + 1..close].trim();
        let args = if args_text == "void" || args_text.is_empty() {
            Vec::new()
        } else {
            args_text.split(',').map(|a| rust_type(&split_param(a))).collect()
        };
        assert!(
            protos.insert(name.clone(), (args, ret)).is_none(),
            "{name} declared twice"
        );
    }
    protos
}

fn rust_protos(lib: &str) -> Protos {
    let block = lib.split("extern \"C\" {").nth(1).expect("no extern block");
    let block = &block[..block.find("\n}").expect("unclosed extern block")];
    let mut protos = Protos::new();
    for stmt in block.split(';') {
        let decl = stmt.split_whitespace().collect::<Vec<_>>().join(" ");
        let Some(rest) = decl.strip_prefix("pub fn ") else {
            continue;
        };
        let open = rest.find('(').unwrap();
        let close = rest.rfind(')').unwrap();
        let name = rest[..open].to_string();
        let args = rest[open + 1..close]
            .split(',')
            .filter(|a| !a.trim().is_empty())
            .map(|a| a.split_once(':').expect("argument without a type").1.trim().to_string())
            .collect();
        let ret = rest[close + 1..]
            .trim()
            .strip_prefix("->")
            .map(|r| r.trim().to_string());
        assert!(
            protos.insert(name.clone(), (args, ret)).is_none(),
            "{name} declared twice"
        );
    }
    protos
}

/// `#define SOGMM_X <integer | (-integer) | (-decimal) | "string">` of the header.
fn header_consts(header: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for line in strip_c_comments(header).lines() {
        let mut it = line.split_whitespace();
        if it.next() != Some("#define") {
            continue;
        }
        let (Some(name), Some(value), None) = (it.next(), it.next(), it.next()) else {
            continue;
        };
        let value = value.trim_start_matches('(').trim_end_matches(')');
        let digits = value.trim_start_matches('-');
        let numeric = digits.chars().all(|c| c.is_ascii_digit() || c == '.')
            && digits.matches('.').count() <= 1
            && digits.chars().any(|c| c.is_ascii_digit());
        if name.starts_with("SOGMM_") && (numeric || value.starts_with('"')) {
            out.insert(name.to_string(), value.to_string());
        }
    }
    out
}

fn rust_consts(lib: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for line in lib.lines() {
        let Some(rest) = line.trim().strip_prefix("pub const ") else {
            continue;
        };
        let (name, rest) = rest.split_once(':').unwrap();
        let value = rest.split_once('=').unwrap().1.trim().trim_end_matches(';').trim();
        out.insert(name.trim().to_string(), value.to_string());
    }
    out
}

/// `typedef R (*sogmm_x_fn)(args);` of the header: name -> (argument types,
/// return type), as header_protos.
fn header_callbacks(header: &str) -> Protos {
    let mut out = Protos::new();
    for stmt in c_declarations(header).split(';') {
        let decl = stmt.split_whitespace().collect::<Vec<_>>().join(" ");
        let Some(rest) = decl.strip_prefix("typedef ") else {
            continue;
        };
        let Some(star) = rest.find("(*") else { continue };
        let ret = rest[..star].trim();
        let name_end = rest[star..].find(')').unwrap() + star;
        let name = rest[star + 2..name_end].trim().to_string();
        let args_text = &rest[name_end + 1..];
        let args_text = args_text.trim().trim_start_matches('(').trim_end_matches(')');
        let args = args_text.split(',').map(|a| rust_type(&split_param(a))).collect();
        let ret = if ret == "void" { None } else { Some(rust_type(ret)) };
        out.insert(name, (args, ret));
    }
    out
}

/// `pub type sogmm_x_fn = Option<unsafe extern "C" fn(a: T, ...) -> R>;` of the crate.
fn rust_callbacks(lib: &str) -> Protos {
    let mut out = Protos::new();
    for stmt in lib.split(';') {
        let decl = stmt.split_whitespace().collect::<Vec<_>>().join(" ");
        let Some(at) = decl.find("pub type ") else { continue };
        let decl = &decl[at + "pub type ".len()..];
        let Some((name, ty)) = decl.split_once(" = Option<unsafe extern \"C\" fn(") else {
            continue;
        };
        let close = ty.rfind(')').unwrap();
        let args = ty[..close]
            .split(',')
            .filter(|a| !a.trim().is_empty())
            .map(|a| a.split_once(':').expect("argument without a name").1.trim().to_string())
            .collect();
        let ret = ty[close + 1..]
            .trim()
            .trim_end_matches('>')
            .trim()
            .strip_prefix("->")
            .map(|r| r.trim().to_string());
        out.insert(name.trim().to_string(), (args, ret));
    }
    out
}

/// The differences of one kind of item between the header (`h`, whose items
/// it calls `h_kind`) and the crate (`r`, `r_kind`): an item missing on one
/// side, or the message `differ` gives for an item on both.
fn compare<V>(
    problems: &mut Vec<String>,
    (h, h_kind): (&BTreeMap<String, V>, &str),
    (r, r_kind): (&BTreeMap<String, V>, &str),
    differ: impl Fn(&str, &V, &V) -> Option<String>,
) {
    for (name, c) in h {
        match r.get(name) {
            None => problems.push(format!("{name}: {h_kind}in sogmm.h, missing in sogmm-sys")),
            Some(rs) => problems.extend(differ(name, c, rs)),
        }
    }
    for name in r.keys().filter(|n| !h.contains_key(*n)) {
        problems.push(format!("{name}: {r_kind}in sogmm-sys, not in sogmm.h"));
    }
}

/// "sogmm.h says ..., sogmm-sys says ..." when the two differ.
fn says<V: PartialEq + std::fmt::Debug>(name: &str, c: &V, rs: &V) -> Option<String> {
    (rs != c).then(|| format!("{name}: sogmm.h says {c:?}, sogmm-sys says {rs:?}"))
}

/// Every difference between the header and the crate, one line each.
fn drift(header: &str, lib: &str) -> Vec<String> {
    let mut problems = Vec::new();
    let (hcb, rcb) = (header_callbacks(header), rust_callbacks(lib));
    compare(&mut problems, (&hcb, "callback type "), (&rcb, "callback type "), says);
    let (h, r) = (header_protos(header), rust_protos(lib));
    compare(&mut problems, (&h, ""), (&r, ""), |name, c, rs| {
        if rs.0.len() != c.0.len() {
            Some(format!(
                "{name}: {} arguments in sogmm.h, {} in sogmm-sys",
                c.0.len(),
                rs.0.len()
            ))
        } else {
            says(name, c, rs)
        }
    });
    let (hc, rc) = (header_consts(header), rust_consts(lib));
    compare(&mut problems, (&hc, "#define "), (&rc, "const "), |name, v, rv| {
        (rv != v).then(|| format!("{name}: {v} in sogmm.h, {rv} in sogmm-sys"))
    });
    problems
}

#[test]
fn sys_crate_matches_header() {
    let problems = drift(HEADER, LIB_RS);
    assert!(
        problems.is_empty(),
        "sogmm-sys drifted from sogmm.h:\n{}",
        problems.join("\n")
    );
    // The parse found the whole API, not an empty subset that trivially agrees.
    assert!(
        header_protos(HEADER).len() >= 44,
        "only {} prototypes parsed",
        header_protos(HEADER).len()
    );
    assert!(
        header_consts(HEADER).len() >= 70,
        "only {} constants parsed",
        header_consts(HEADER).len()
    );
}

/// The checker itself catches each kind of drift (a header edited as a future
/// change would edit it).
#[test]
fn drift_is_detected() {
    let cases = [
        (
            "size_t capacity, size_t* n_points",
            "uint32_t capacity, size_t* n_points",
            "sogmm_frame_to_points_f32",
        ),
        ("uint64_t seed,\n", "uint64_t seed, int extra,\n", "arguments"),
        (
            "const sogmm_model* model, double* pose_out",
            "sogmm_model* model, double* pose_out",
            "sogmm_model_get_pose",
        ),
        (
            "SOGMM_API uint32_t sogmm_abi_version",
            "SOGMM_API int32_t sogmm_abi_version",
            "sogmm_abi_version",
        ),
        (
            "#define SOGMM_E_CANCELLED (-12)",
            "#define SOGMM_E_CANCELLED (-12)\n#define SOGMM_E_NEXT (-13)",
            "SOGMM_E_NEXT",
        ),
        (
            "double log_likelihood,\n                                     void* user_data);",
            "float log_likelihood,\n                                     void* user_data);",
            "sogmm_progress_fn",
        ),
        (
            "#define SOGMM_OPT_N_INIT 109",
            "#define SOGMM_OPT_N_INIT 110",
            "SOGMM_OPT_N_INIT",
        ),
        (
            "SOGMM_API void sogmm_buffer_free(sogmm_buffer* buffer);",
            "",
            "sogmm_buffer_free",
        ),
        (
            "SOGMM_API sogmm_status sogmm_model_clear_pose(sogmm_model* model);",
            "SOGMM_API sogmm_status sogmm_model_clear_pose(sogmm_model* model);\nSOGMM_API void sogmm_new(void);",
            "sogmm_new",
        ),
    ];
    for (from, to, expect) in cases {
        assert!(HEADER.contains(from), "test case out of date: {from:?}");
        let problems = drift(&HEADER.replacen(from, to, 1), LIB_RS);
        assert!(
            problems.iter().any(|p| p.contains(expect)),
            "edit {from:?} -> {to:?} not reported (got {problems:?})"
        );
    }
}

#[test]
fn c_types_translate() {
    assert_eq!(rust_type("const char**"), "*mut *const c_char");
    assert_eq!(rust_type("sogmm_model**"), "*mut *mut sogmm_model");
    assert_eq!(rust_type("const void*"), "*const c_void");
    assert_eq!(rust_type("size_t"), "usize");
}
