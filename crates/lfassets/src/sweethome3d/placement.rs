//! Where a Sweet Home 3D piece goes in a room. The catalogues say nothing of it beyond an
//! elevation, so it is guessed from names, tags and sizes; also which entries are no
//! furniture at all, and what others can stand on.

use lfformat::catalog::AssetPlacement;
use std::collections::HashMap;

/// Lower-case words of a name and its tags.
fn words(name: &str, tags: &str) -> Vec<String> {
    format!("{name} {tags}")
        .to_lowercase()
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(String::from)
        .collect()
}

/// Words (of a name or tag) of small pieces that still stand on the floor.
const FLOOR_STANDING: &str = "seat chair stool nightstand potty bin dustbin trash shoes slippers \
    sneakers bootie mocassin hood radiator";
/// Words of storage and fitted pieces that stand with their back against a wall.
const FITTED: &str = "cabinet wardrobe closet bookcase bookshelf shelves shelf cupboard dresser \
    chest sideboard vanity washbasin sink fridge refrigerator freezer dishwasher washer dryer \
    cooker oven stove fireplace radiator heater toilet toilets bidet urinal shower hood";

/// Where a Sweet Home 3D piece goes in a room, from its name, category, tags, size
/// `[width, height, depth]` and elevation (metres). Tuned on the 920 entries of Debian's
/// libraries; the first rule that applies wins:
///
/// 1. **ceiling**: names with ceiling / pendant / chandelier / smoke detector, and lights or
///    fans (category `Lights`, or lamp / light / fan / lantern in the name) whose top
///    (elevation + height) reaches 2.4 m — Sweet Home 3D's ceiling is 2.5 m — except hoods,
///    cabinets, heaters and showers, which reach it from a wall. A ceiling-named piece that
///    does not hang (top below 2.4 m, yet raised) falls through to wall_hung.
/// 2. **wall_hung**: any elevation ≥ 5 cm. In these catalogues every raised piece is
///    wall-mounted, low ones included (sockets at 22 cm, radiators at 10–20 cm, towels,
///    washbasins at 35–50 cm, curtains at 8 cm), so the threshold is not 0.3 m.
/// 3. **floor_cover**: rug, carpet, mat, doormat, bathmat, tatami no higher than 6 cm.
/// 4. **on_top**: small light things — height < 0.6 m and footprint < 0.5 m, flat ones
///    (height < 0.15 m, footprint < 0.8 m: hobs, trays, folded clothes), and appliances,
///    electronics and TVs below 0.55 m with a footprint < 0.9 m (coffee machines, fryers,
///    flat TVs) — except seats, tables, bins, shoes, potties, hoods and radiators, which stand
///    on the floor.
/// 5. **wall**: storage and fitted pieces by name or tag (cabinet, wardrobe, closet,
///    bookcase, shelves, cupboard, dresser, chest, vanity, sink, washbasin, fridge, freezer,
///    dishwasher, washer, dryer, cooker, oven, stove, fireplace, radiator, heater, toilet,
///    bidet, urinal, shower, hood, upright piano; not kitchen islands), and wide shallow tall
///    pieces (depth ≤ 0.45 m, width ≥ 2 × depth, height ≥ 1 m: screens, racks, brooms).
/// 6. **floor**: the rest (tables, seats, beds, sofas, plants, appliances …).
pub fn placement(
    name: &str,
    category: &str,
    tags: &str,
    size: [f32; 3],
    elevation: f32,
) -> AssetPlacement {
    let w = words(name, tags);
    let has = |list: &str| list.split_whitespace().any(|l| w.iter().any(|x| x == l));
    let [width, height, depth] = size;
    let top = elevation + height;
    let ceiling_named = has("ceiling pendant chandelier") || (has("smoke") && has("detector"));
    let light = category == "Lights" || has("lamp light fan lantern");
    let wall_fitted = has("hood cabinet heater shower");
    if (ceiling_named && (top >= 2.4 || elevation == 0.0)) || (light && top >= 2.4 && !wall_fitted)
    {
        return AssetPlacement::Ceiling;
    }
    if elevation >= 0.05 {
        return AssetPlacement::WallHung;
    }
    let cover = has("rug rugs carpet mat doormat bathmat tatami");
    if cover && height <= 0.06 {
        return AssetPlacement::FloorCover;
    }
    let footprint = width.max(depth);
    let appliance = has("appliance electronics television tv computer");
    let small = (height < 0.6 && footprint < 0.5)
        || (height < 0.15 && footprint < 0.8)
        || (appliance && height < 0.55 && footprint < 0.9);
    let floor_standing = has(FLOOR_STANDING) || name.to_lowercase().trim_end().ends_with("table");
    if small && !floor_standing {
        return AssetPlacement::OnTop;
    }
    let fitted = has(FITTED) || (has("piano") && !has("grand bench"));
    let panel = depth <= 0.45 && width >= 2.0 * depth && height >= 1.0;
    if (fitted && !has("island")) || panel {
        return AssetPlacement::Wall;
    }
    AssetPlacement::Floor
}

/// Kitchen hoods hang above the cooker even where the catalogue leaves their elevation at 0
/// (Scopia's `kitchenHood`): 1.5 m then, a usual height above a 0.9 m worktop.
pub(super) fn hood_elevation(name: &str, elevation: f32) -> f32 {
    let hood = words(name, "").iter().any(|w| w == "hood");
    if hood && elevation == 0.0 {
        1.5
    } else {
        elevation
    }
}

/// Heights (metres above the bottom) others can stand on. Sweet Home 3D's
/// `dropOnTopElevation` (cm) gives it: kept when it is at least 15 % of the height (lower
/// values are the insides of baskets, vases, boxes and bathtubs, where a dropped piece would be
/// hidden) and not above the top; a negative value means "nothing goes on it". Without the key
/// Sweet Home 3D drops on the top: kept as the height for floor and wall pieces up to 1.3 m
/// (tables, desks, chests, low cabinets), not for taller ones (wardrobes, fridges, curtains).
pub(super) fn surfaces(
    drop_cm: Option<f32>,
    height_cm: f32,
    placement: AssetPlacement,
) -> Vec<f32> {
    match drop_cm {
        Some(d) if d > 0.0 && d >= 0.15 * height_cm && d <= height_cm => vec![d / 100.0],
        Some(_) => vec![],
        None => {
            let standing = matches!(placement, AssetPlacement::Floor | AssetPlacement::Wall);
            if standing && height_cm <= 130.0 {
                vec![height_cm / 100.0]
            } else {
                vec![]
            }
        }
    }
}

/// Why an entry is skipped before looking at its files, if it is: doors and windows, people,
/// vehicles, exterior and garden pieces, architecture, and the default catalogue's light-source
/// markers (a sphere that stands for a light, not a visible object).
pub(super) fn excluded(fields: &HashMap<String, String>) -> Option<&'static str> {
    let get = |k: &str| fields.get(k).map(String::as_str).unwrap_or("");
    if get("doorOrWindow").trim() == "true" {
        return Some("door or window");
    }
    let w = words(get("name"), get("tags"));
    let has = |list: &str| list.split_whitespace().any(|l| w.iter().any(|x| x == l));
    match get("category").trim() {
        "Characters" => return Some("people (category Characters)"),
        "Vehicles" => return Some("vehicles (category Vehicles)"),
        "Exterior" => return Some("exterior (category Exterior, or tagged Exterior/Garden/Road)"),
        "Doors and windows" | "Staircases" => {
            return Some("architecture (staircases, shutters, screen doors)");
        }
        _ => {}
    }
    if has("exterior garden road") {
        return Some("exterior (category Exterior, or tagged Exterior/Garden/Road)");
    }
    if get("model").ends_with("/lightSource.obj") || (has("light") && has("source")) {
        return Some("light-source marker (no visible object)");
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placement_rules() {
        use AssetPlacement::*;
        let p = |name, cat, tags, s: [f32; 3], e| placement(name, cat, tags, s, e);
        assert_eq!(
            p("Pendant lamp", "Lights", "", [0.6, 0.8, 0.6], 1.7),
            Ceiling
        );
        assert_eq!(
            p("Wall spotlight", "Lights", "", [0.06, 0.1, 0.23], 1.9),
            WallHung
        );
        assert_eq!(p("Hood", "Kitchen", "", [0.6, 0.94, 0.52], 1.56), WallHung);
        assert_eq!(hood_elevation("Range hood", 0.0), 1.5);
        assert_eq!(hood_elevation("Hood", 1.56), 1.56);
        assert_eq!(
            p(
                "Wall switch",
                "Miscellaneous",
                "",
                [0.085, 0.085, 0.011],
                1.15
            ),
            WallHung
        );
        assert_eq!(
            p(
                "Oriental rug",
                "Living room",
                "Carpet",
                [1.86, 0.025, 2.58],
                0.0
            ),
            FloorCover
        );
        assert_eq!(p("Teapot", "Kitchen", "", [0.22, 0.21, 0.15], 0.0), OnTop);
        assert_eq!(
            p("Stool", "Living room", "Chair, Seat", [0.4, 0.46, 0.4], 0.0),
            Floor
        );
        assert_eq!(
            p(
                "Bedside table",
                "Bedroom",
                "Nightstand",
                [0.38, 0.5, 0.38],
                0.0
            ),
            Floor
        );
        assert_eq!(
            p("Wardrobe", "Bedroom", "Closet", [1.0, 1.65, 0.54], 0.0),
            Wall
        );
        assert_eq!(p("Table", "Living room", "", [1.5, 0.74, 0.75], 0.0), Floor);
        let tv = "Blend Swap, Appliance, Television";
        assert_eq!(
            p("TV", "Living room", tv, [0.775, 0.508, 0.142], 0.0),
            OnTop
        );
        assert_eq!(
            p("Island", "Kitchen", "Cabinet", [0.94, 0.83, 0.7], 0.0),
            Floor
        );
    }
}
