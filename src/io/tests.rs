use super::*;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("orthosim-io-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

#[test]
fn an_atomic_write_replaces_the_whole_file_and_leaves_no_temporary() {
    let dir = scratch("atomic");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("a.txt");
    write_atomic(&path, "first, longer text").unwrap();
    write_atomic(&path, "second").unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
    assert_eq!(listing(&dir), ["a.txt"]);
    // Into a missing folder: an error naming the file, and nothing left.
    let e = write_atomic(&dir.join("missing/b.txt"), "x").unwrap_err();
    assert!(e.to_string().contains("missing/b.txt: cannot write"), "{e}");
    assert_eq!(listing(&dir), ["a.txt"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_input_is_never_overwritten_even_through_another_path() {
    let dir = scratch("inputs");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let input = dir.join("case.ron");
    std::fs::write(&input, "x").unwrap();
    let other = dir.join("sub/../case.ron");
    let e = refuse_overwriting(&other, &[&input]).unwrap_err();
    assert!(matches!(e, OutputError::WouldOverwriteInput { .. }), "{e}");
    assert!(refuse_overwriting(&dir.join("new.ron"), &[&input]).is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn outputs_are_checked_whole_before_anything_is_created() {
    let dir = scratch("checked");
    let long = "n".repeat(MAX_FILE_NAME_BYTES + 1);
    let paths = vec![dir.join("11.stl"), dir.join(format!("{long}.ron"))];
    let e = OutputSet::new(&dir, paths, &[]).unwrap_err();
    assert!(matches!(e, OutputError::NameTooLong { .. }), "{e}");
    assert!(!dir.exists(), "a refused set creates no folder");
    let twice = vec![dir.join("a"), dir.join("a")];
    assert!(matches!(
        OutputSet::new(&dir, twice, &[]).unwrap_err(),
        OutputError::Duplicate { .. }
    ));
    let e = OutputSet::new(&dir, vec![dir.join("x").join("..")], &[]).unwrap_err();
    assert!(matches!(e, OutputError::NoFileName { .. }), "{e}");
    let huge = PathBuf::from("d/".repeat(MAX_PATH_BYTES / 2 + 1)).join("f");
    assert!(matches!(
        check_output(&huge, &[]).unwrap_err(),
        OutputError::PathTooLong { .. }
    ));
}

#[test]
fn a_set_is_written_all_or_nothing() {
    let dir = scratch("set");
    let (a, b) = (dir.join("a.stl"), dir.join("b.ron"));
    // Abandoned half-way: no file, no temporary, no folder.
    let mut set = OutputSet::new(&dir, vec![a.clone(), b.clone()], &[]).unwrap();
    set.write(&a, b"solid").unwrap();
    assert_eq!(listing(&dir).len(), 1, "one temporary while writing");
    drop(set);
    assert!(!dir.exists(), "{:?}", listing(&dir));
    // A commit with a file never written fails and leaves nothing either.
    let mut set = OutputSet::new(&dir, vec![a.clone(), b.clone()], &[]).unwrap();
    set.write(&a, b"solid").unwrap();
    assert!(set.commit().is_err());
    assert!(!dir.exists());
    // Written whole: both files, nothing else.
    let mut set = OutputSet::new(&dir, vec![a.clone(), b.clone()], &[]).unwrap();
    set.write(&a, b"solid").unwrap();
    set.write(&b, "Case()").unwrap();
    assert!(
        set.write(&dir.join("c"), "x").is_err(),
        "only checked outputs"
    );
    set.commit().unwrap();
    assert_eq!(listing(&dir), ["a.stl", "b.ron"]);
    assert_eq!(std::fs::read_to_string(&b).unwrap(), "Case()");
    // A folder the set did not create stays when a later set is abandoned.
    drop(OutputSet::new(&dir, vec![dir.join("c")], &[]).unwrap());
    assert_eq!(listing(&dir), ["a.stl", "b.ron"]);
    let _ = std::fs::remove_dir_all(&dir);
}
