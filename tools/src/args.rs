//! The examples' command lines: `KEY=VALUE` words, read by key.

/// The `KEY=VALUE` words of a command line (other words are passed over).
pub struct Args(Vec<(String, String)>);

impl Args {
    /// The process's own arguments.
    pub fn from_env() -> Args {
        Args::of(std::env::args().skip(1))
    }

    /// The given words.
    pub fn of(words: impl IntoIterator<Item = String>) -> Args {
        Args(
            words
                .into_iter()
                .filter_map(|a| a.split_once('=').map(|(k, v)| (k.to_string(), v.to_string())))
                .collect(),
        )
    }

    /// The value of `key`, if given.
    pub fn get(&self, key: &str) -> Option<String> {
        self.0.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone())
    }

    /// The number given for `key`, or `default`; panics (an example's usage error) on a word
    /// that is not a number.
    pub fn num(&self, key: &str, default: f64) -> f64 {
        self.get(key).map_or(default, |v| {
            v.parse().unwrap_or_else(|_| panic!("{key}={v}: not a number"))
        })
    }

    /// The `COLSxROWS` given for `key`, or `default`.
    pub fn size(&self, key: &str, default: (u32, u32)) -> (u32, u32) {
        self.get(key).map_or(default, |s| {
            let (a, b) = s
                .split_once('x')
                .unwrap_or_else(|| panic!("{key}={s}: COLSxROWS"));
            (
                a.parse().unwrap_or_else(|_| panic!("{key}={s}: cols")),
                b.parse().unwrap_or_else(|_| panic!("{key}={s}: rows")),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_numbers_and_sizes() {
        let a = Args::of(["freq=0.5,2", "dt=0.01", "size=61x41", "stray"].map(String::from));
        assert_eq!(a.get("freq").as_deref(), Some("0.5,2"));
        assert_eq!(a.num("dt", 1.0), 0.01);
        assert_eq!(a.num("amp", 0.04), 0.04);
        assert_eq!(a.size("size", (1, 1)), (61, 41));
        assert_eq!(a.get("stray"), None);
    }
}
