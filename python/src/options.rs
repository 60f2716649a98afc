//! A run's options from Python keywords: every field of the library's `Overrides`, by its name, read through serde, so nothing here spells them.

use forkbench_trial::trial::Overrides;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The options `kwargs` set (`None` values are unset). A keyword that is not an option is
/// refused with the option names, and a value of the wrong type with the option's name.
pub fn overrides(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Overrides> {
    let Some(kwargs) = kwargs else {
        return Ok(Overrides::default());
    };
    let names = Overrides::field_names();
    let mut map = serde_json::Map::new();
    for (k, v) in kwargs.iter() {
        let key: String = k.extract()?;
        if !names.contains(&key.as_str()) {
            return Err(PyTypeError::new_err(format!(
                "unexpected keyword argument {key:?} (a run's options: {})",
                names.join(", ")
            )));
        }
        if v.is_none() {
            continue;
        }
        let bad = |why: String| PyTypeError::new_err(format!("{key}: {why}"));
        let text = crate::convert::json_text(&v).map_err(|e| bad(e.to_string()))?;
        let mut value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| bad(format!("{text}: {e}")))?;
        if key == "truck" {
            layout_as_code(&mut value).map_err(bad)?;
        }
        let one = serde_json::Value::Object([(key.clone(), value.clone())].into_iter().collect());
        serde_json::from_value::<Overrides>(one).map_err(|e| bad(e.to_string()))?;
        map.insert(key, value);
    }
    serde_json::from_value(serde_json::Value::Object(map))
        .map_err(|e| PyTypeError::new_err(e.to_string()))
}

/// A truck's `layout` given by name (`"pallet_stacker"`, as a truck file says it) rides
/// among the numeric settings as its code, as the truck file's reader puts it.
fn layout_as_code(truck: &mut serde_json::Value) -> Result<(), String> {
    let Some(slot) = truck.get_mut("layout") else {
        return Ok(());
    };
    if let Some(name) = slot.as_str() {
        let layout = forkbench_core::TruckLayout::from_key(name).ok_or_else(|| {
            format!(
                "layout: unknown layout {name:?} (known: {})",
                forkbench_core::TruckLayout::keys()
            )
        })?;
        *slot = serde_json::Value::from(layout.code());
    }
    Ok(())
}
