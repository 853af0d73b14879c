//! Sweet Home 3D's built-in material names: OBJ files of its libraries use names (`glass`,
//! `dkgrey`, `redwood` …) that the program supplies itself and no `.mtl` file defines. This is
//! our own table for them, so such models are not drawn in a default grey.

/// A material of our built-in table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuiltinMaterial {
    pub diffuse: [f32; 3],
    pub specular: f32,
    pub shininess: f32,
    /// Opacity (`d`); `Tr` = 1 − `d`.
    pub opacity: f32,
}

/// Words that make a material glass-like (transparent).
const GLASS_WORDS: &str =
    "glass glas verre vidrio vitre vetro cristal crystal transparent window windshield";

/// Colour words of material names and the colours we give them (our own values).
const COLOUR_WORDS: &[(&str, [f32; 3])] = &[
    ("black", [0.02, 0.02, 0.02]),
    ("ebony", [0.08, 0.06, 0.05]),
    ("white", [0.85, 0.85, 0.85]),
    ("ivory", [0.86, 0.83, 0.72]),
    ("bone", [0.84, 0.80, 0.70]),
    ("teeth", [0.90, 0.88, 0.80]),
    ("cream", [0.88, 0.84, 0.70]),
    ("grey", [0.50, 0.50, 0.50]),
    ("gray", [0.50, 0.50, 0.50]),
    ("silver", [0.75, 0.75, 0.77]),
    ("chrome", [0.80, 0.80, 0.82]),
    ("metal", [0.60, 0.60, 0.62]),
    ("steel", [0.62, 0.63, 0.65]),
    ("iron", [0.40, 0.40, 0.42]),
    ("alu", [0.78, 0.78, 0.80]),
    ("gold", [0.80, 0.62, 0.25]),
    ("brass", [0.76, 0.62, 0.30]),
    ("bronze", [0.62, 0.42, 0.22]),
    ("copper", [0.72, 0.42, 0.26]),
    ("brown", [0.40, 0.25, 0.12]),
    ("wood", [0.55, 0.38, 0.20]),
    ("oak", [0.62, 0.46, 0.28]),
    ("walnut", [0.38, 0.25, 0.15]),
    ("pine", [0.76, 0.60, 0.38]),
    ("redwood", [0.50, 0.22, 0.13]),
    ("mahogany", [0.42, 0.16, 0.10]),
    ("tan", [0.70, 0.55, 0.38]),
    ("blonde", [0.82, 0.70, 0.45]),
    ("sand", [0.76, 0.69, 0.54]),
    ("beige", [0.80, 0.74, 0.60]),
    ("stone", [0.58, 0.56, 0.52]),
    ("skin", [0.85, 0.64, 0.52]),
    ("flesh", [0.87, 0.66, 0.55]),
    ("lips", [0.62, 0.28, 0.28]),
    ("red", [0.70, 0.08, 0.06]),
    ("ruby", [0.60, 0.05, 0.12]),
    ("pink", [0.90, 0.55, 0.65]),
    ("orange", [0.90, 0.45, 0.08]),
    ("flame", [1.00, 0.55, 0.12]),
    ("amber", [0.85, 0.55, 0.10]),
    ("yellow", [0.90, 0.80, 0.12]),
    ("green", [0.15, 0.50, 0.15]),
    ("olive", [0.45, 0.45, 0.15]),
    ("teal", [0.10, 0.45, 0.45]),
    ("blue", [0.12, 0.22, 0.65]),
    ("blu", [0.12, 0.22, 0.65]),
    ("sky", [0.45, 0.65, 0.90]),
    ("iris", [0.35, 0.30, 0.70]),
    ("lavender", [0.70, 0.60, 0.85]),
    ("lavendar", [0.70, 0.60, 0.85]),
    ("purple", [0.45, 0.20, 0.55]),
    ("violet", [0.50, 0.25, 0.65]),
];

/// Words of shiny metals (stronger highlight).
const METAL_WORDS: &str = "silver chrome metal steel iron alu gold brass bronze copper";

/// A plausible material for one of Sweet Home 3D's built-in material names (used in OBJ files
/// without a definition): the mean of the colour words found in the name (longest first, so
/// `redwood` is not `red`), darkened by `dk`/`dark` (twice for `dkdk`), lightened by
/// `lt`/`light`/`brt`; neutral grey when no colour word is found. Every glass-like name
/// ([`GLASS_WORDS`]) is transparent: opacity 0.2.
pub fn builtin_material(name: &str) -> BuiltinMaterial {
    let lower = name.to_lowercase();
    let glass = GLASS_WORDS.split(' ').any(|w| lower.contains(w));
    let mut rest = lower.clone();
    let mut words: Vec<&(&str, [f32; 3])> = COLOUR_WORDS.iter().collect();
    words.sort_by_key(|(w, _)| std::cmp::Reverse(w.len()));
    let mut sum = [0.0f32; 3];
    let mut found = 0;
    for (word, colour) in words {
        while let Some(i) = rest.find(word) {
            rest.replace_range(i..i + word.len(), &" ".repeat(word.len()));
            for k in 0..3 {
                sum[k] += colour[k];
            }
            found += 1;
        }
    }
    let mut diffuse = match found {
        0 if glass => [0.80, 0.88, 0.90],
        0 => [0.60, 0.60, 0.60],
        n => sum.map(|s| s / n as f32),
    };
    if rest.contains("dkdk") {
        diffuse = diffuse.map(|c| c * 0.35);
    } else if rest.contains("dk") || rest.contains("dark") {
        diffuse = diffuse.map(|c| c * 0.55);
    } else if rest.contains("lt") || rest.contains("light") || rest.contains("brt") {
        diffuse = diffuse.map(|c| c + (1.0 - c) * 0.4);
    }
    let metal = METAL_WORDS.split(' ').any(|w| lower.contains(w));
    let (specular, shininess) = match (glass, metal) {
        (true, _) => (0.9, 300.0),
        (false, true) => (0.6, 120.0),
        _ => (0.1, 20.0),
    };
    BuiltinMaterial {
        diffuse,
        specular,
        shininess,
        opacity: if glass { 0.2 } else { 1.0 },
    }
}

/// MTL text defining `names` with [`builtin_material`].
pub(super) fn builtin_mtl<'a>(names: impl IntoIterator<Item = &'a String>) -> String {
    let mut s = String::from(
        "# Written by lfgen assets fetch sweethome3d: lfgen's own colours for material names\n\
         # that Sweet Home 3D supplies itself (never defined in the library's .mtl files).\n",
    );
    for name in names {
        let m = builtin_material(name);
        let [r, g, b] = m.diffuse;
        let (k, d) = (m.specular, m.opacity);
        let illum = if d < 1.0 { 4 } else { 2 };
        s.push_str(&format!("\nnewmtl {name}\n"));
        s.push_str(&format!(
            "Ka {:.3} {:.3} {:.3}\n",
            r * 0.2,
            g * 0.2,
            b * 0.2
        ));
        s.push_str(&format!(
            "Kd {r:.3} {g:.3} {b:.3}\nKs {k:.2} {k:.2} {k:.2}\n"
        ));
        s.push_str(&format!(
            "Ns {:.0}\nd {d:.2}\nTr {:.2}\nillum {illum}\n",
            m.shininess,
            1.0 - d
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn materials() {
        for glass in [
            "glass",
            "glasstransparent",
            "cristal_blanco",
            "Verre",
            "vidrio",
            "Fenster_Glas",
            "window",
        ] {
            let m = builtin_material(glass);
            assert!((0.15..=0.3).contains(&m.opacity), "{glass}: {m:?}");
        }
        let luminance = |n: &str| builtin_material(n).diffuse.iter().sum::<f32>() / 3.0;
        assert!(luminance("black") < 0.05 && luminance("white") > 0.8);
        assert!(
            luminance("dkgrey") < luminance("grey") && luminance("grey") < luminance("flltgrey")
        );
        let red = builtin_material("red").diffuse;
        assert!(red[0] > 0.5 && red[1] < 0.2);
        let redwood = builtin_material("redwood").diffuse;
        assert!(
            redwood[1] > 0.15,
            "redwood is a wood, not pure red: {redwood:?}"
        );
        assert_eq!(builtin_material("white").opacity, 1.0);
    }
}
