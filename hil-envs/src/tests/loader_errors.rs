//! Dataset loader errors name the file, the record and the field (unit
//! tests: damaging a saved dataset's arrays needs the private `.npy` writer).

use std::path::{Path, PathBuf};

use hil_core::HilError;

use crate::dataset::FoodDataset;
use crate::generate::SyntheticFoods;
use crate::npy::{NpyArray, read_npy, write_npy};

fn small() -> FoodDataset {
    SyntheticFoods::small().generate().unwrap().dataset
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-envs-unit-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Saves a small dataset, then lets `corrupt` damage it, and returns the load error.
fn load_error(name: &str, corrupt: impl FnOnce(&Path)) -> HilError {
    let mut ds = small();
    ds.foods.truncate(2);
    let dir = tmp(name);
    ds.save(&dir).unwrap();
    corrupt(&dir);
    let e = FoodDataset::load(&dir).unwrap_err();
    std::fs::remove_dir_all(&dir).unwrap();
    e
}

fn edit_array(path: &Path, f: impl FnOnce(&mut NpyArray)) {
    let mut a = read_npy(path).unwrap();
    f(&mut a);
    write_npy(path, &a).unwrap();
}

/// Where an error puts the fault: the file, and the record (1-based line
/// or row; 0 when the whole file is at fault) if it names one.
fn located(e: &HilError) -> (PathBuf, usize) {
    match e {
        HilError::Data { path, record, .. } => (path.clone(), *record),
        HilError::Config(c) => (c.path.clone(), c.line),
        other => panic!("not a located error: {other:?}"),
    }
}

fn assert_at(e: &HilError, file: &str, record: Option<usize>) {
    let (path, at) = located(e);
    assert!(path.ends_with(file), "{e:?}");
    if let Some(r) = record {
        assert_eq!(at, r, "{e:?}");
    }
}

#[test]
fn loader_errors_name_file_record_and_field() {
    // A non-finite context: the row (record 5) of that food's array.
    let e = load_error("nan", |d| {
        edit_array(&d.join("apple/contexts.npy"), |a| {
            a.data[224 * 4 + 7] = f64::NAN
        })
    });
    assert!(matches!(e, HilError::Data { .. }), "{e:?}");
    assert_at(&e, "apple/contexts.npy", Some(5));

    // A success probability outside [0, 1]: its row.
    let e = load_error("prob", |d| {
        edit_array(&d.join("banana/success.npy"), |a| a.data[6 * 2 + 3] = 1.5)
    });
    assert!(matches!(e, HilError::Data { .. }), "{e:?}");
    assert_at(&e, "banana/success.npy", Some(3));

    // A manifest dimension the arrays do not have: the array, as that field.
    let e = load_error("dim", |d| {
        let m = std::fs::read_to_string(d.join("dataset.toml")).unwrap();
        std::fs::write(
            d.join("dataset.toml"),
            m.replace("context_dim = 224", "context_dim = 128"),
        )
        .unwrap();
    });
    assert!(
        matches!(e, HilError::Data { ref field, .. } if field == "contexts"),
        "{e:?}"
    );
    assert_at(&e, "apple/contexts.npy", None);

    // A setting index past the manifest's settings: its row.
    let e = load_error("setting", |d| {
        edit_array(&d.join("apple/settings.npy"), |a| a.data[2] = 7.0)
    });
    assert!(matches!(e, HilError::Data { .. }), "{e:?}");
    assert_at(&e, "apple/settings.npy", Some(3));

    // An unknown manifest key: its line and name.
    let e = load_error("unknown-field", |d| {
        let m = std::fs::read_to_string(d.join("dataset.toml")).unwrap();
        std::fs::write(d.join("dataset.toml"), format!("colour = 1\n{m}")).unwrap();
    });
    assert!(
        matches!(e, HilError::Config(ref c) if c.field.as_deref() == Some("colour")),
        "{e:?}"
    );
    assert_at(&e, "dataset.toml", Some(1));

    // An array with a row missing: the array, as that field.
    let e = load_error("rows", |d| {
        edit_array(&d.join("banana/success.npy"), |a| {
            a.shape[0] -= 1;
            a.data.truncate(a.data.len() - 6);
        })
    });
    assert!(
        matches!(e, HilError::Data { ref field, .. } if field == "success"),
        "{e:?}"
    );
    assert_at(&e, "banana/success.npy", None);
}
