//! Property tests of the food-dataset readers (unit tests: the `.npy`
//! reader is private to the crate): mutated `.npy` files and
//! mutated manifests (truncations, bit flips, junk, huge and non-finite
//! numbers) are either read or refused with an error that names the file
//! at fault, never a panic; nothing is allocated from a declared size
//! before the data is there to back it.

use std::path::{Path, PathBuf};

use crate::dataset::FoodDataset;
use crate::npy::{NpyArray, read_npy_bytes, write_npy, write_npy_bytes};
use hil_conformance::mutate::mutated;
use hil_core::HilError;
use proptest::prelude::*;

/// The file an error names, whatever its kind.
fn named_file(e: &HilError) -> Option<&Path> {
    match e {
        HilError::Data { path, .. } | HilError::Io { path, .. } => Some(path),
        HilError::Config(c) => Some(&c.path),
        _ => None,
    }
}

/// `.npy` bytes as NumPy writes them, for several element types.
fn npy_bases() -> Vec<Vec<u8>> {
    let f8 =
        write_npy_bytes(&NpyArray::new(vec![2, 3], vec![0.5, -1.0, 2.0, 1e-3, 0.0, 7.0]).unwrap());
    let mut out = vec![f8];
    for (descr, shape, data) in [
        (
            "<f4",
            "(2,)",
            [1.5f32.to_le_bytes(), (-2.0f32).to_le_bytes()].concat(),
        ),
        (
            "<i4",
            "(2, 1)",
            [3i32.to_le_bytes(), (-4i32).to_le_bytes()].concat(),
        ),
        ("|u1", "(3,)", vec![0, 1, 1]),
    ] {
        let mut header =
            format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        header.push_str(&" ".repeat(128 - 10 - header.len() - 1));
        header.push('\n');
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend_from_slice(&(header.len() as u16).to_le_bytes());
        b.extend_from_slice(header.as_bytes());
        b.extend_from_slice(&data);
        out.push(b);
    }
    out
}

#[test]
fn the_unmutated_arrays_are_valid() {
    for b in npy_bases() {
        read_npy_bytes(&b, Path::new("a.npy")).unwrap();
    }
}

/// A small valid dataset in `dir`: one food, two images, two actions.
fn write_dataset(dir: &Path) -> String {
    let food = dir.join("kiwi");
    std::fs::create_dir_all(&food).unwrap();
    let arrays = [
        ("contexts", vec![2, 3], vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6]),
        ("success", vec![2, 2], vec![0.5, 0.25, 1.0, 0.0]),
        ("settings", vec![2], vec![0.0, 1.0]),
        (
            "outcomes",
            vec![2, 2, 2],
            vec![1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0],
        ),
    ];
    for (name, shape, data) in arrays {
        write_npy(
            &food.join(format!("{name}.npy")),
            &NpyArray::new(shape, data).unwrap(),
        )
        .unwrap();
    }
    "name = \"fuzz\"\n\
     provenance = \"made up\"\n\
     actions = [\"VS0\", \"TV90\"]\n\
     settings = [\"isolated\", \"wall\"]\n\
     context_dim = 3\n\
     \n\
     [[foods]]\n\
     name = \"kiwi\"\n\
     contexts = \"kiwi/contexts.npy\"\n\
     success = \"kiwi/success.npy\"\n\
     settings = \"kiwi/settings.npy\"\n\
     outcomes = \"kiwi/outcomes.npy\"\n"
        .to_string()
}

fn fuzz_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hil-dataset-fuzz-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, ..ProptestConfig::default() })]

    #[test]
    fn mutated_arrays_are_read_or_refused_naming_the_file(
        bytes in proptest::sample::select(npy_bases()).prop_flat_map(|b| mutated(b, 4))
    ) {
        let path = Path::new("fuzz/a.npy");
        match read_npy_bytes(&bytes, path) {
            Ok(a) => {
                let n: usize = a.shape.iter().product();
                prop_assert_eq!(n, a.data.len());
            }
            Err(HilError::Data { path: p, .. }) => prop_assert_eq!(p.as_path(), path),
            Err(other) => prop_assert!(false, "not a data error: {other:?}"),
        }
    }
}

proptest! {
    // Each case writes and loads a dataset, so fewer cases.
    #![proptest_config(ProptestConfig { cases: 120, ..ProptestConfig::default() })]

    #[test]
    fn mutated_manifests_are_read_or_refused_naming_a_file_of_the_dataset(
        bytes in mutated(write_dataset(&fuzz_dir("manifest")).into_bytes(), 4)
    ) {
        let dir = fuzz_dir("manifest");
        let manifest = dir.join("dataset.toml");
        std::fs::write(&manifest, &bytes).unwrap();
        if let Err(e) = FoodDataset::load(&manifest) {
            let named = named_file(&e);
            prop_assert!(named.is_some_and(|p| p.starts_with(&dir)), "{e:?}");
        }
    }

    #[test]
    fn a_dataset_with_a_mutated_array_is_read_or_refused_naming_that_array(
        which in proptest::sample::select(vec!["contexts", "success", "settings", "outcomes"]),
        edits in proptest::collection::vec(hil_conformance::mutate::mutation(), 1..4)
    ) {
        let dir = fuzz_dir(&format!("array-{which}"));
        let manifest = write_dataset(&dir);
        std::fs::write(dir.join("dataset.toml"), manifest).unwrap();
        let array = dir.join("kiwi").join(format!("{which}.npy"));
        let mut bytes = std::fs::read(&array).unwrap();
        for m in &edits {
            m.apply(&mut bytes);
        }
        std::fs::write(&array, &bytes).unwrap();
        if let Err(e) = FoodDataset::load(&dir) {
            // The mutated array is at fault (or, when it now reads as
            // values the manifest does not allow, the manifest check names
            // the dataset).
            let named = named_file(&e);
            prop_assert!(
                named.is_some_and(|p| p == array || p == dir.join("dataset.toml")),
                "{e:?}"
            );
        }
    }
}
