//! Random damage to a JSON value, shared by the scene and config fuzzers.

use rand::{Rng, RngExt};
use serde_json::Value;

/// Numbers that break naive code: zero, negatives, huge, off-by-one at integer limits.
const HOSTILE: [f64; 14] = [
    0.0,
    -1.0,
    -5.0,
    0.5,
    2.0,
    1e-30,
    1e25,
    1e38,
    -1e38,
    1e308,
    4294967295.0,
    4294967296.0,
    18446744073709551615.0,
    9.0,
];

/// Every path to a value in `v` (object keys and array indices).
fn paths(v: &Value, here: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    out.push(here.clone());
    match v {
        Value::Object(m) => {
            for (k, c) in m {
                here.push(Step::Key(k.clone()));
                paths(c, here, out);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                here.push(Step::Index(i));
                paths(c, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

fn at<'a>(v: &'a mut Value, path: &[Step]) -> &'a mut Value {
    path.iter().fold(v, |v, s| match s {
        Step::Key(k) => &mut v[k.as_str()],
        Step::Index(i) => &mut v[*i],
    })
}

/// One random damage to one random place of `v`.
pub fn mutate(v: &mut Value, rng: &mut impl Rng) {
    let mut all = Vec::new();
    paths(v, &mut Vec::new(), &mut all);
    let path = &all[rng.random_range(0..all.len())];
    let target = at(v, path);
    let roll = rng.random_range(0..10);
    let hostile = serde_json::json!(HOSTILE[rng.random_range(0..HOSTILE.len())]);
    if roll <= 4 && target.is_number() {
        *target = hostile;
        return;
    }
    if roll <= 3 {
        match target {
            Value::Array(a) if !a.is_empty() => {
                match rng.random_range(0..3) {
                    0 => a.clear(),
                    1 => a.truncate(a.len() - 1),
                    _ => {
                        let copy = a[rng.random_range(0..a.len())].clone();
                        a.extend(std::iter::repeat_n(copy, rng.random_range(1..4)));
                    }
                }
                return;
            }
            Value::Object(m) if !m.is_empty() => {
                if rng.random_bool(0.5) {
                    let key = m.keys().nth(rng.random_range(0..m.len())).unwrap().clone();
                    m.remove(&key);
                } else {
                    m.insert("unknown_field".into(), Value::Bool(true));
                }
                return;
            }
            _ => {}
        }
    }
    *target = match roll {
        5 => Value::Null,
        6 => serde_json::json!("x"),
        7 => serde_json::json!([]),
        8 => serde_json::json!(-1),
        _ => hostile,
    };
}
