//! Rust results into Python objects, and Rust errors into Python exceptions that name the file, field and reason.

use forkbench_trial::ScenarioError as FileError;
use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList};
use serde_json::Value;

create_exception!(
    forkbench,
    ScenarioError,
    PyValueError,
    "A scenario, world or option that cannot be used; `file`, `field` and `reason` say which and why."
);
create_exception!(
    forkbench,
    BatchError,
    PyRuntimeError,
    "A batch that could not run or be read (its output directory, settings or records)."
);
create_exception!(
    forkbench,
    RecordingError,
    PyOSError,
    "A recording that could not be written."
);

/// A scenario error as a `ScenarioError` carrying `file`, `field` (None when the whole
/// file is at fault) and `reason`.
pub fn scenario_error(py: Python<'_>, e: &FileError) -> PyErr {
    let (file, field, reason) = match e {
        FileError::Read { file, cause } => (file.clone(), None, cause.to_string()),
        FileError::Parse { file, message } => (file.clone(), None, message.clone()),
        FileError::Invalid {
            file,
            field,
            reason,
        } => (file.clone(), Some(field.clone()), reason.clone()),
        FileError::CaseNeeded { file, count, known } => (
            file.clone(),
            Some("case".to_owned()),
            format!("{count} cases; choose one (cases: {known})"),
        ),
        FileError::UnknownCase { file, case, known } => (
            file.clone(),
            Some("case".to_owned()),
            format!("no case named {case:?} (cases: {known})"),
        ),
    };
    let err = ScenarioError::new_err(e.to_string());
    let value = err.value(py);
    let set = || -> PyResult<()> {
        value.setattr("file", file)?;
        value.setattr("field", field)?;
        value.setattr("reason", reason)
    };
    match set() {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// A JSON value as the Python object `json.loads` would give.
pub fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let items = a
                .iter()
                .map(|x| to_py(py, x))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Object(m) => {
            let d = PyDict::new(py);
            for (k, x) in m {
                d.set_item(k, to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A Python object as JSON text, as `json.dumps` writes it (the way back from [`to_py`]).
pub fn json_text(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    obj.py()
        .import("json")?
        .call_method1("dumps", (obj,))?
        .extract()
}

/// Any serialisable result as its Python object.
pub fn serde_to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    t: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(t).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    to_py(py, &v)
}
