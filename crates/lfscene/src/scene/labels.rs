//! Semantic classes of a scene's objects, for the class-id ground truth.
//!
//! A class is the kind of thing an object is part of, read from the object's name as the
//! built-in generator writes it (`object_{i}_{kind}_{part}`, `wall_back`, `light_2`,
//! `outside_sky`, …). The classes of the built-in generator have fixed ids ([`CLASSES`]), so a
//! class id means the same in every scene of every dataset; any other class (catalogue assets,
//! imported glTF nodes) gets the next free id in the order the scene first names it, and the
//! scene's `ids.json` names every id it uses.

/// The built-in classes, id = position + 1 (0: no surface). New classes go at the end, so the
/// ids of existing ones never change.
pub const CLASSES: &[&str] = &[
    "floor",
    "ceiling",
    "wall",
    "skirting",
    "light",
    "window",
    "sky",
    "tree",
    "building",
    "table",
    "coffeetable",
    "glasstable",
    "chair",
    "meshchair",
    "stool",
    "bookshelf",
    "glassshelf",
    "cabinet",
    "sofa",
    "armchair",
    "bed",
    "floorlamp",
    "plant",
    "screen",
    "curtain",
    "pedestal",
    "crate",
    "rug",
    "pictureframe",
    "tablelamp",
    "vase",
    "bottle",
    "drinkingglass",
    "bowl",
    "bookstack",
    "smallbox",
];

/// What lies outside a room's openings, by the name after `outside_`: the class it belongs to.
const OUTSIDE: &[(&str, &str)] = &[
    ("pane", "window"),
    ("bar", "window"),
    ("reveal", "wall"),
    ("corridor", "wall"),
    ("sky", "sky"),
    ("woods", "tree"),
    ("tree", "tree"),
    ("building", "building"),
];

/// The class of an object named `name`.
pub fn class_of(name: &str) -> &str {
    if let Some(rest) = name.strip_prefix("object_") {
        // `{i}_{kind}_{part}`: the kind (a catalogue id may itself hold `_`).
        let kind = rest.split_once('_').map_or(rest, |(_, k)| k);
        return kind.rsplit_once('_').map_or(kind, |(k, _)| k);
    }
    if let Some(what) = name.strip_prefix("outside_") {
        return OUTSIDE.iter().find(|o| o.0 == what).map_or(name, |o| o.1);
    }
    if name.starts_with("wall_") {
        return "wall";
    }
    if name.strip_prefix("light_").is_some_and(is_number) {
        return "light";
    }
    // An imported glTF node of several primitives names each `{node} primitive {k}`.
    match name.rsplit_once(" primitive ") {
        Some((node, k)) if is_number(k) => node,
        _ => name,
    }
}

fn is_number(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())
}

/// The class ids of a scene: every id it uses with its name, and each object's id.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneClasses {
    /// `(id, name)` of every class some object has, ascending by id.
    pub names: Vec<(u32, String)>,
    /// The class id of each object, in the order of the names given to [`SceneClasses::new`]
    /// (a scene's `objects`).
    pub of_object: Vec<u32>,
}

impl SceneClasses {
    /// The classes of the objects named `names`.
    pub fn new<'a>(names: impl IntoIterator<Item = &'a str>) -> Self {
        let mut extra: Vec<String> = Vec::new();
        let mut of_object = Vec::new();
        for name in names {
            let class = class_of(name);
            let id = match CLASSES.iter().position(|&c| c == class) {
                Some(i) => i + 1,
                None => match extra.iter().position(|c| c == class) {
                    Some(i) => CLASSES.len() + i + 1,
                    None => {
                        extra.push(class.to_string());
                        CLASSES.len() + extra.len()
                    }
                },
            };
            of_object.push(id as u32);
        }
        let mut used: Vec<u32> = of_object.clone();
        used.sort_unstable();
        used.dedup();
        let name = |id: u32| match (id as usize).checked_sub(CLASSES.len() + 1) {
            Some(i) => extra[i].clone(),
            None => CLASSES[id as usize - 1].to_string(),
        };
        let names = used.into_iter().map(|id| (id, name(id))).collect();
        Self { names, of_object }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_of_the_builtin_generator_give_their_kind() {
        let cases = [
            ("object_3_armchair_leg", "armchair"),
            ("object_12_glassshelf_book", "glassshelf"),
            ("object_4_sweethome3d_chair_1_mesh", "sweethome3d_chair_1"),
            ("wall_back", "wall"),
            ("light_3", "light"),
            ("outside_pane", "window"),
            ("outside_woods", "tree"),
            ("floor", "floor"),
            ("skirting", "skirting"),
            ("Lamp primitive 2", "Lamp"),
            ("light_fitting", "light_fitting"),
        ];
        for (name, class) in cases {
            assert_eq!(class_of(name), class, "{name}");
        }
    }

    #[test]
    fn builtin_classes_keep_their_ids_and_others_follow_in_order() {
        let names = [
            "wall_left",
            "object_0_rug_rug",
            "Teapot",
            "floor",
            "Teapot",
            "Cup",
        ];
        let c = SceneClasses::new(names);
        let n = CLASSES.len() as u32;
        assert_eq!(c.of_object, [3, 28, n + 1, 1, n + 1, n + 2]);
        let names: Vec<(u32, &str)> = c.names.iter().map(|(i, s)| (*i, s.as_str())).collect();
        assert_eq!(
            names,
            [
                (1, "floor"),
                (3, "wall"),
                (28, "rug"),
                (n + 1, "Teapot"),
                (n + 2, "Cup")
            ]
        );
    }
}
