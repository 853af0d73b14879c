//! The rule every test that drives an outside tool follows (`tests/skip`): under CI a missing
//! tool fails the test, elsewhere it is a printed skip.

mod skip;

use skip::{skip_under, under_ci};
use std::ffi::OsStr;

#[test]
fn ci_is_any_value_but_empty_0_or_false() {
    for (value, ci) in [
        (None, false),
        (Some(""), false),
        (Some("0"), false),
        (Some("false"), false),
        (Some("true"), true),
        (Some("1"), true),
    ] {
        assert_eq!(under_ci(value.map(OsStr::new)), ci, "CI={value:?}");
    }
}

#[test]
fn outside_ci_a_missing_tool_is_a_skip() {
    skip_under(false, "povray is not installed");
}

#[test]
#[should_panic(
    expected = "cannot run under CI, which must run every test: povray is not installed"
)]
fn under_ci_a_missing_tool_is_a_failure_with_the_reason() {
    skip_under(true, "povray is not installed");
}
