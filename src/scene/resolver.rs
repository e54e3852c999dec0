//! File resolution for scene assets: a file name is looked up relative to the folders of the
//! `<path value="..."/>` entries (most recent first) and then the main scene file's folder,
//! as Mitsuba's `FileResolver` does.

use super::error::{Error, Result, SrcPos};
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Default)]
pub struct FileResolver {
    /// Search folders, highest priority first.
    pub paths: Vec<PathBuf>,
}

impl FileResolver {
    /// A resolver that searches the folder of `scene_file`.
    pub fn for_scene(scene_file: &Path) -> FileResolver {
        let dir = scene_file.parent().map(|p| p.to_path_buf()).unwrap_or_default();
        FileResolver { paths: vec![if dir.as_os_str().is_empty() { PathBuf::from(".") } else { dir }] }
    }

    /// Add a search folder with the highest priority (a `<path>` entry).
    pub fn prepend(&mut self, dir: PathBuf) {
        self.paths.insert(0, dir);
    }

    /// Resolve `name`: absolute paths as they are, else the first search folder that has it.
    pub fn resolve(&self, name: &str) -> Option<PathBuf> {
        let p = Path::new(name);
        if p.is_absolute() {
            return p.exists().then(|| p.to_path_buf());
        }
        self.paths.iter().map(|d| d.join(p)).find(|c| c.exists())
    }

    /// Resolve or fail with an error at `pos` naming the folders searched.
    pub fn resolve_at(&self, name: &str, pos: &SrcPos) -> Result<PathBuf> {
        self.resolve(name).ok_or_else(|| {
            let dirs: Vec<String> = self.paths.iter().map(|d| d.display().to_string()).collect();
            Error::at(pos, format!("file \"{}\" not found (searched: {})", name, dirs.join(", ")))
        })
    }
}
