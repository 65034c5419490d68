//! A response cache on disk, so that re-running an evaluation costs no
//! request and gives the same table: one JSON file per request, named by
//! the SHA-256 of the model, the messages (images by the hash of their
//! bytes) and the sampling parameters.

use super::client::{LlmConfig, LlmError, Message, Part};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// A directory of cached replies.
#[derive(Debug, Clone)]
pub struct Cache {
    dir: PathBuf,
}

impl Cache {
    /// A cache in `dir` (created on the first write).
    pub fn new(dir: impl Into<PathBuf>) -> Cache {
        Cache { dir: dir.into() }
    }

    /// The per-user default: `$XDG_CACHE_HOME/logicrag/lmm`, else
    /// `~/.cache/logicrag/lmm`, else `./.logicrag-cache/lmm`.
    pub fn default_dir() -> PathBuf {
        let base = std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
            .unwrap_or_else(|| PathBuf::from(".logicrag-cache"));
        base.join("logicrag").join("lmm")
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The key of a request: what the server sees that can change its reply.
    pub fn key(config: &LlmConfig, messages: &[Message]) -> String {
        let mut h = Sha256::new();
        h.update(b"logicrag-lmm-cache-v1\0");
        h.update(config.base_url.as_bytes());
        h.update(b"\0");
        h.update(config.model.as_bytes());
        h.update(b"\0");
        h.update(config.temperature.to_bits().to_le_bytes());
        h.update(config.max_tokens.to_le_bytes());
        for m in messages {
            h.update(m.role.as_bytes());
            h.update(b"\0");
            for p in &m.parts {
                match p {
                    Part::Text(t) => {
                        h.update(b"t");
                        h.update((t.len() as u64).to_le_bytes());
                        h.update(t.as_bytes());
                    }
                    Part::Png(bytes) => {
                        h.update(b"i");
                        h.update(Sha256::digest(bytes));
                    }
                }
            }
            h.update(b"\x01");
        }
        hex(&h.finalize())
    }

    fn path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.json"))
    }

    /// The cached reply for `key`, if any.
    pub fn get(&self, key: &str) -> Result<Option<String>, LlmError> {
        let p = self.path(key);
        match std::fs::read_to_string(&p) {
            Ok(text) => {
                let v: serde_json::Value =
                    serde_json::from_str(&text).map_err(|e| LlmError::Cache {
                        path: p.display().to_string(),
                        source: std::io::Error::new(std::io::ErrorKind::InvalidData, e),
                    })?;
                Ok(v.get("reply").and_then(|r| r.as_str()).map(str::to_string))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(source) => Err(LlmError::Cache {
                path: p.display().to_string(),
                source,
            }),
        }
    }

    /// Stores a reply (written to a temporary file, then renamed, so a
    /// concurrent reader never sees half a file).
    pub(crate) fn put(&self, key: &str, model: &str, reply: &str) -> Result<(), LlmError> {
        let err = |source| LlmError::Cache {
            path: self.dir.display().to_string(),
            source,
        };
        std::fs::create_dir_all(&self.dir).map_err(err)?;
        let p = self.path(key);
        let tmp = self.dir.join(format!(".{key}.{}.tmp", std::process::id()));
        let body = serde_json::json!({"model": model, "reply": reply});
        std::fs::write(&tmp, body.to_string()).map_err(err)?;
        std::fs::rename(&tmp, &p).map_err(err)
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_follow_content_not_identity() {
        let c = LlmConfig::new("http://127.0.0.1:1/v1", "m", None).expect("config");
        let a = vec![Message {
            role: "user".into(),
            parts: vec![Part::Text("q".into()), Part::Png(vec![1, 2, 3])],
        }];
        let mut b = a.clone();
        assert_eq!(Cache::key(&c, &a), Cache::key(&c, &b));
        b[0].parts[1] = Part::Png(vec![1, 2, 4]);
        assert_ne!(Cache::key(&c, &a), Cache::key(&c, &b));
        let other = LlmConfig::new("http://127.0.0.1:1/v1", "m2", None).expect("config");
        assert_ne!(Cache::key(&c, &a), Cache::key(&other, &a));
    }

    #[test]
    fn a_reply_round_trips() {
        let dir = std::env::temp_dir().join(format!("logicrag-cache-{}", std::process::id()));
        let cache = Cache::new(&dir);
        assert_eq!(cache.get("k").expect("read"), None);
        cache.put("k", "m", "Yes, it is.").expect("write");
        assert_eq!(
            cache.get("k").expect("read").as_deref(),
            Some("Yes, it is.")
        );
        std::fs::remove_dir_all(&dir).expect("clean");
    }
}
