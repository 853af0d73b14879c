//! Licences: which one a library, an entry or an OBJ header states (as an SPDX-style id),
//! whether it is free enough for a dataset, and what `ATTRIBUTION.md` says about it.

/// An SPDX-style licence id for a licence text or name (a `LICENSE.TXT`, a catalogue's
/// `license` key, an OBJ header), or `None` when it names none we know.
pub fn license_id(text: &str) -> Option<String> {
    let t = text.to_lowercase();
    let version = ["4.0", "3.0", "2.5", "2.0", "1.0"]
        .into_iter()
        .find(|v| t.contains(v))
        .unwrap_or("3.0");
    let has = |phrases: &str| phrases.split('|').any(|p| t.contains(p));
    let id = if has("noncommercial|non-commercial|by-nc") {
        format!("CC-BY-NC-{version}")
    } else if has("noderivatives|no derivative|by-nd") {
        format!("CC-BY-ND-{version}")
    } else if has("creative commons zero|publicdomain/zero|choose/zero|cc0|cc-0") {
        "CC0-1.0".into()
    } else if has("sharealike|share alike|by-sa") {
        format!("CC-BY-SA-{version}")
    } else if has("attribution|cc-by|licenses/by/") {
        let us = has("united states|/by/3.0/us");
        format!("CC-BY-{version}{}", if us { "-US" } else { "" })
    } else if has("general public license|gnu gpl") {
        "GPL-2.0-or-later".into()
    } else if has("public domain") {
        "public-domain".into()
    } else {
        return None;
    };
    Some(id)
}

/// Whether a licence id is free for a dataset anyone may use: CC0, public domain, CC-BY and
/// CC-BY-SA, GPL (and expressions of them). Non-commercial (NC), no-derivatives (ND) and
/// unknown licences are not.
pub fn is_free_license(id: &str) -> bool {
    id.split(" OR ").any(|part| {
        let p = part.trim();
        let known = p == "CC0-1.0"
            || p == "public-domain"
            || p.starts_with("CC-BY-")
            || p.starts_with("GPL-");
        known && !p.contains("-NC") && !p.contains("-ND")
    })
}

/// The dual licence stated in the header comment of Sweet Home 3D's own OBJ files ("at your
/// choice, under the CC-BY … 3.0 … or under the terms of the GNU General Public License").
pub(super) fn obj_header_license(obj: &[u8]) -> Option<String> {
    let head: String = obj
        .split(|&b| b == b'\n')
        .take(15)
        .filter(|l| l.first() == Some(&b'#'))
        .map(|l| String::from_utf8_lossy(l).to_lowercase())
        .collect::<Vec<_>>()
        .join(" ");
    let dual = head.contains("at your choice")
        && head.contains("creative commons attribution 3")
        && head.contains("general public license");
    dual.then(|| "CC-BY-3.0 OR GPL-2.0-or-later".to_string())
}

/// Where to read a licence's text.
pub(super) fn license_url(id: &str) -> &'static str {
    match id {
        "CC0-1.0" => "https://creativecommons.org/publicdomain/zero/1.0/",
        "CC-BY-3.0" => "https://creativecommons.org/licenses/by/3.0/",
        "CC-BY-3.0-US" => "https://creativecommons.org/licenses/by/3.0/us/",
        "CC-BY-4.0" => "https://creativecommons.org/licenses/by/4.0/",
        "GPL-2.0-or-later" => "https://www.gnu.org/licenses/old-licenses/gpl-2.0.html",
        "CC-BY-3.0 OR GPL-2.0-or-later" => {
            "https://creativecommons.org/licenses/by/3.0/ or \
             https://www.gnu.org/licenses/old-licenses/gpl-2.0.html"
        }
        _ => "",
    }
}

/// One line on what a licence asks of users.
pub(super) fn license_summary(id: &str) -> &'static str {
    if id == "CC0-1.0" || id == "public-domain" {
        "public-domain dedication: any use, no conditions (crediting the authors is still kind)"
    } else if id.contains(" OR ") {
        "at your choice CC-BY 3.0 (credit the author) or the GNU GPL (version 2 or later)"
    } else if id.starts_with("CC-BY-SA") {
        "any use, including commercial, crediting the author; adaptations under the same licence"
    } else if id.starts_with("CC-BY-") && is_free_license(id) {
        "any use, including commercial and adaptations, crediting the author and linking the \
         licence"
    } else if id.starts_with("GPL-") {
        "copyleft: redistributions and derived works under the GNU GPL"
    } else {
        "not a free licence: read the library's LICENSE.TXT before using these models"
    }
}

/// The licence of the `Files: *` paragraph of a Debian machine-readable copyright file, as
/// an SPDX id (`GPL-2+` → `GPL-2.0-or-later`).
pub(super) fn debian_files_license(copyright: &str) -> Option<String> {
    for paragraph in copyright.split("\n\n") {
        let mut lines = paragraph.lines();
        if lines.next().map(str::trim) != Some("Files: *") {
            continue;
        }
        let license = lines.find_map(|l| l.strip_prefix("License:"))?.trim();
        let spdx = match license {
            "GPL-2+" => "GPL-2.0-or-later",
            "GPL-2" => "GPL-2.0-only",
            "GPL-3+" => "GPL-3.0-or-later",
            other => other,
        };
        return Some(spdx.to_string());
    }
    None
}

/// The `(C) …` / `Copyright …` line of a licence text, if any.
pub(super) fn copyright_line(text: &str) -> Option<String> {
    text.lines()
        .map(str::trim)
        .find(|l| l.starts_with("(C)") || l.to_lowercase().starts_with("copyright"))
        .map(String::from)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn licences() {
        assert_eq!(
            license_id("Creative Commons Zero (Public Domain)").as_deref(),
            Some("CC0-1.0")
        );
        assert_eq!(
            license_id(
                "Attribution 3.0 United States http://creativecommons.org/licenses/by/3.0/us/"
            )
            .as_deref(),
            Some("CC-BY-3.0-US")
        );
        assert_eq!(
            license_id("Creative Commons Attribution 3.0 Unported").as_deref(),
            Some("CC-BY-3.0")
        );
        assert_eq!(license_id("CC BY-NC 4.0").as_deref(), Some("CC-BY-NC-4.0"));
        assert!(is_free_license("CC-BY-3.0 OR GPL-2.0-or-later"));
        assert!(!is_free_license("CC-BY-NC-4.0"));
        assert!(!is_free_license("unknown"));
    }
}
