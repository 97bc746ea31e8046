//! The one error type of the library, and the words its messages are made of. Every variant maps
//! onto the exit codes of `docs/conventions.md`: anything that stops a command is exit 2, with one
//! line that names the file and the problem.
//!
//! The library is called by more than one front end (the command line, a Python binding), and
//! each names its options in its own way: `--max-pixels` on the command line, `max_pixels=` in
//! Python. So no message of the library names an option itself. A message is [`Words`]: text,
//! and the [`Setting`]s it refers to, kept as data; a front end's [`Wording`] turns each setting
//! into its own name when the message is shown. An [`Error::Usage`] also says which setting was
//! refused and the value given, for a front end that reports it its own way.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// An option of the library's work that a message refers to: the one that was refused, or the
/// one that would fix the problem. Each front end names them its own way ([`Wording`]);
/// [`Setting::name`] is the neutral name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Setting {
    /// The green-channel convention of a normal map, OpenGL (+Y) or DirectX (-Y): what a map
    /// given to `bake` is converted from.
    Convention,
    /// The one material to bake, by name.
    Material,
    /// The most pixels an image file given to the library may have.
    MaxPixels,
    /// Whether a URI may name a file outside the asset's folder (a switch).
    AllowOutside,
    /// Whether bitangents are written beside the tangents (a switch).
    Bitangents,
    /// Whether valid tangents already present are replaced (a switch).
    Overwrite,
    /// Tangents for every primitive with UVs, not only where a material needs them (a switch).
    All,
    /// Supersampling of a preview: samples per pixel along each axis.
    Ssaa,
    /// The size of an image made: a baked map's texels or a preview's pixels.
    Size,
    /// Samples per texel along each axis when baking from HIGH meshes.
    Samples,
    /// How far in front of LOW a baking ray starts looking for HIGH.
    RayFront,
    /// How far behind LOW a baking ray still looks for HIGH.
    RayBack,
    /// The node whose mesh is LOW, when a mesh is shown by several.
    Node,
    /// The sample depth of a normal map written: 8 or 16 bits.
    Bits,
    /// What the alpha channel of a normal map written holds (the height).
    Alpha,
    /// Which channel of a height image holds the height.
    Channel,
    /// How strongly heights tilt the normals.
    Strength,
    /// The surface height of a height map's `h = 1`, in the mesh's (or metres') units.
    HeightRange,
    /// The size of one texel on the surface, in the units of the height range.
    TexelSize,
    /// The height map holds depth: white is deep (a switch).
    Invert,
    /// A height map to bake into a normal map.
    Height,
    /// A normal map to bake.
    Normal,
    /// The HIGH meshes whose surface is baked onto LOW.
    High,
    /// The KTX2 codec's effort or quality: UASTC's pack level, ETC1S's quality.
    Ktx2Quality,
    /// The cap of specular antialiasing's roughness widening, in GGX alpha.
    SpecularAaThreshold,
    /// A preview camera's vertical field of view, in degrees.
    Fov,
    /// A preview camera's turn about the vertical axis, in degrees.
    Yaw,
    /// A preview camera's tilt, in degrees.
    Pitch,
    /// A preview camera's distance from the scene's centre.
    Distance,
    /// A preview's ambient light.
    Ambient,
    /// A preview's specular strength.
    Specular,
    /// A preview's specular exponent.
    Shininess,
}

impl Setting {
    /// Every setting, in declaration order (a new variant goes here too: the front ends' tests
    /// check each has a name).
    pub const EVERY: [Setting; 32] = [
        Setting::Convention,
        Setting::Material,
        Setting::MaxPixels,
        Setting::AllowOutside,
        Setting::Bitangents,
        Setting::Overwrite,
        Setting::All,
        Setting::Ssaa,
        Setting::Size,
        Setting::Samples,
        Setting::RayFront,
        Setting::RayBack,
        Setting::Node,
        Setting::Bits,
        Setting::Alpha,
        Setting::Channel,
        Setting::Strength,
        Setting::HeightRange,
        Setting::TexelSize,
        Setting::Invert,
        Setting::Height,
        Setting::Normal,
        Setting::High,
        Setting::Ktx2Quality,
        Setting::SpecularAaThreshold,
        Setting::Fov,
        Setting::Yaw,
        Setting::Pitch,
        Setting::Distance,
        Setting::Ambient,
        Setting::Specular,
        Setting::Shininess,
    ];

    /// The neutral name: lower case, words joined by `_` (`max_pixels`).
    pub fn name(self) -> &'static str {
        match self {
            Setting::Convention => "convention",
            Setting::Material => "material",
            Setting::MaxPixels => "max_pixels",
            Setting::AllowOutside => "allow_outside",
            Setting::Bitangents => "bitangents",
            Setting::Overwrite => "overwrite",
            Setting::All => "all",
            Setting::Ssaa => "ssaa",
            Setting::Size => "size",
            Setting::Samples => "samples",
            Setting::RayFront => "ray_front",
            Setting::RayBack => "ray_back",
            Setting::Node => "node",
            Setting::Bits => "bits",
            Setting::Alpha => "alpha",
            Setting::Channel => "channel",
            Setting::Strength => "strength",
            Setting::HeightRange => "height_range",
            Setting::TexelSize => "texel_size",
            Setting::Invert => "invert",
            Setting::Height => "height",
            Setting::Normal => "normal",
            Setting::High => "high",
            Setting::Ktx2Quality => "ktx2_quality",
            Setting::SpecularAaThreshold => "specular_aa_threshold",
            Setting::Fov => "fov",
            Setting::Yaw => "yaw",
            Setting::Pitch => "pitch",
            Setting::Distance => "distance",
            Setting::Ambient => "ambient",
            Setting::Specular => "specular",
            Setting::Shininess => "shininess",
        }
    }
}

/// How a front end names settings in the messages it shows. Only [`Wording::name`] is required;
/// the others default to the neutral forms built on it.
pub trait Wording: Send + Sync {
    /// The setting itself: `--max-pixels`, `max_pixels`.
    fn name(&self, s: Setting) -> String;
    /// The setting given a value: `--convention directx`, `convention="directx"`.
    fn given(&self, s: Setting, value: &str) -> String {
        format!("{}={value}", self.name(s))
    }
    /// A switch turned on: `--allow-outside`, `allow_outside=True`.
    fn on(&self, s: Setting) -> String {
        self.name(s)
    }
}

/// The wording of a caller that installed none: [`Setting::name`], `name=value`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Neutral;

impl Wording for Neutral {
    fn name(&self, s: Setting) -> String {
        s.name().to_string()
    }
}

static WORDING: OnceLock<&'static dyn Wording> = OnceLock::new();

/// Makes `w` the wording of every message shown from now on (`Display`, and the notes the library
/// writes into its reports as text). A front end installs its own once, before any work; the first
/// install wins (false if one was there). Without one, messages read [`Neutral`].
///
/// A process-wide choice rather than a parameter, because messages become text in places no
/// parameter reaches: an error turned into a report's note on a worker thread, a report
/// serialised by the caller.
pub fn install(w: &'static dyn Wording) -> bool {
    WORDING.set(w).is_ok()
}

/// The installed wording, or [`Neutral`].
pub fn wording() -> &'static dyn Wording {
    WORDING.get().copied().unwrap_or(&Neutral)
}

/// One part of a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Piece {
    Text(String),
    /// The setting named (`the limit (--max-pixels)`).
    Name(Setting),
    /// The setting with a value (`pass --convention directx`).
    Given(Setting, String),
    /// A switch turned on (`pass --allow-outside`).
    On(Setting),
}

/// A message: text and the settings it refers to, worded when it is shown.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Words(Vec<Piece>);

impl Words {
    pub fn new() -> Words {
        Words::default()
    }

    /// Appends text.
    pub fn text(mut self, t: impl Into<String>) -> Words {
        let t = t.into();
        match self.0.last_mut() {
            Some(Piece::Text(last)) => last.push_str(&t),
            _ if t.is_empty() => {}
            _ => self.0.push(Piece::Text(t)),
        }
        self
    }

    /// Appends the setting's name.
    pub fn name(mut self, s: Setting) -> Words {
        self.0.push(Piece::Name(s));
        self
    }

    /// Appends the setting given `value`.
    pub fn given(mut self, s: Setting, value: impl std::fmt::Display) -> Words {
        self.0.push(Piece::Given(s, value.to_string()));
        self
    }

    /// Appends the switch `s` turned on.
    pub fn on(mut self, s: Setting) -> Words {
        self.0.push(Piece::On(s));
        self
    }

    /// Appends another message.
    pub fn then(mut self, more: Words) -> Words {
        for p in more.0 {
            self = match p {
                Piece::Text(t) => self.text(t),
                p => {
                    self.0.push(p);
                    self
                }
            };
        }
        self
    }

    /// The same message after `prefix`.
    pub fn after(self, prefix: impl Into<String>) -> Words {
        Words::new().text(prefix).then(self)
    }

    pub fn pieces(&self) -> &[Piece] {
        &self.0
    }

    /// The settings the message refers to, in order.
    pub fn settings(&self) -> impl Iterator<Item = Setting> + '_ {
        self.0.iter().filter_map(|p| match p {
            Piece::Text(_) => None,
            Piece::Name(s) | Piece::Given(s, _) | Piece::On(s) => Some(*s),
        })
    }

    /// The message in `w`'s words.
    pub fn worded(&self, w: &dyn Wording) -> String {
        self.0
            .iter()
            .map(|p| match p {
                Piece::Text(t) => t.clone(),
                Piece::Name(s) => w.name(*s),
                Piece::Given(s, v) => w.given(*s, v),
                Piece::On(s) => w.on(*s),
            })
            .collect()
    }
}

/// In the installed wording ([`install`]).
impl std::fmt::Display for Words {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.worded(wording()))
    }
}

impl From<String> for Words {
    fn from(t: String) -> Words {
        Words::new().text(t)
    }
}

impl From<&str> for Words {
    fn from(t: &str) -> Words {
        Words::new().text(t)
    }
}

/// Why a command could not finish. `Display` words it in the installed wording ([`install`]);
/// [`Error::worded`] in any.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input could not be used: unreadable, malformed or unsupported.
    #[error("{}: {msg}", path.display())]
    Input {
        path: PathBuf,
        msg: Words,
        /// What a library reported underneath, when a [`Fault`] carried it.
        #[source]
        cause: Option<Box<dyn std::error::Error + Send + Sync + 'static>>,
    },
    /// The caller asks for something impossible: `setting` (when one setting is to blame) cannot
    /// be `value` (when the value is the problem); `msg` says why and what would do.
    #[error("{msg}")]
    Usage { setting: Option<Setting>, value: Option<String>, msg: Words },
    /// An output could not be written.
    #[error("{}: cannot write: {msg}", path.display())]
    Output { path: PathBuf, msg: String },
}

impl Error {
    pub fn input(path: impl AsRef<Path>, msg: impl Into<Words>) -> Self {
        Error::Input { path: path.as_ref().to_path_buf(), msg: msg.into(), cause: None }
    }
    /// A reader's [`Fault`] in the file `path`, its cause kept.
    pub fn in_file(path: impl AsRef<Path>, fault: Fault) -> Self {
        Error::Input { path: path.as_ref().to_path_buf(), msg: fault.msg, cause: fault.source }
    }
    pub fn output(path: impl AsRef<Path>, msg: impl std::fmt::Display) -> Self {
        Error::Output { path: path.as_ref().to_path_buf(), msg: msg.to_string() }
    }
    /// A request that cannot be met, no one setting to blame.
    pub fn usage(msg: impl Into<Words>) -> Self {
        Error::Usage { setting: None, value: None, msg: msg.into() }
    }
    /// `setting` refused; `value`, when the value given is what is wrong.
    pub fn setting(setting: Setting, value: Option<String>, msg: impl Into<Words>) -> Self {
        Error::Usage { setting: Some(setting), value, msg: msg.into() }
    }
    /// The message after the file's name, when there is one.
    pub fn message(&self) -> std::borrow::Cow<'_, Words> {
        match self {
            Error::Input { msg, .. } | Error::Usage { msg, .. } => std::borrow::Cow::Borrowed(msg),
            Error::Output { msg, .. } => std::borrow::Cow::Owned(Words::from(format!("cannot write: {msg}"))),
        }
    }
    /// The whole line, in `w`'s words.
    pub fn worded(&self, w: &dyn Wording) -> String {
        match self {
            Error::Input { path, msg, .. } => format!("{}: {}", path.display(), msg.worded(w)),
            Error::Usage { msg, .. } => msg.worded(w),
            Error::Output { .. } => self.to_string(),
        }
    }
    /// The process exit code the conventions give this error.
    pub fn exit_code(&self) -> u8 {
        2
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What went wrong inside some bytes, before the caller knows which file they came from: the
/// words a user reads and, where a library reported it, the error underneath (kept as the
/// `source`, so the chain is there for whoever walks it). The readers' and decoders' error;
/// [`Error::in_file`] turns it into an [`Error`] that names the file.
#[derive(Debug, thiserror::Error)]
#[error("{msg}")]
pub struct Fault {
    msg: Words,
    #[source]
    source: Option<Box<dyn std::error::Error + Send + Sync + 'static>>,
}

impl Fault {
    pub fn new(msg: impl Into<Words>) -> Self {
        Fault { msg: msg.into(), source: None }
    }

    /// A fault whose cause is `source`; `msg` says what it meant here.
    pub fn caused_by(msg: impl Into<Words>, source: impl std::error::Error + Send + Sync + 'static) -> Self {
        Fault { msg: msg.into(), source: Some(Box::new(source)) }
    }

    /// The same fault, its words prefixed with where it happened.
    pub fn at(self, place: impl std::fmt::Display) -> Self {
        Fault { msg: self.msg.after(format!("{place}: ")), source: self.source }
    }
}

impl From<String> for Fault {
    fn from(msg: String) -> Self {
        Fault::new(msg)
    }
}

impl From<&str> for Fault {
    fn from(msg: &str) -> Self {
        Fault::new(msg)
    }
}

impl From<Words> for Fault {
    fn from(msg: Words) -> Self {
        Fault::new(msg)
    }
}

/// A reader's result, its file not named yet.
pub type Faulty<T> = std::result::Result<T, Fault>;

#[cfg(test)]
mod tests {
    use super::*;

    struct Flags;
    impl Wording for Flags {
        fn name(&self, s: Setting) -> String {
            format!("--{}", s.name().replace('_', "-"))
        }
        fn given(&self, s: Setting, v: &str) -> String {
            format!("{} {v}", self.name(s))
        }
    }

    #[test]
    fn a_message_keeps_its_settings_and_is_worded_by_the_front_end() {
        let w = Words::from("declared OpenGL; pass ").given(Setting::Convention, "directx").text(" to convert it");
        assert_eq!(w.worded(&Neutral), "declared OpenGL; pass convention=directx to convert it");
        assert_eq!(w.worded(&Flags), "declared OpenGL; pass --convention directx to convert it");
        assert_eq!(w.settings().collect::<Vec<_>>(), [Setting::Convention]);
        let e = Error::in_file("a.png", Fault::new(w).at("image 0"));
        assert_eq!(e.worded(&Flags), "a.png: image 0: declared OpenGL; pass --convention directx to convert it");
        // No wording is installed in the library's tests: `Display` is neutral.
        assert_eq!(e.to_string(), "a.png: image 0: declared OpenGL; pass convention=directx to convert it");
    }

    #[test]
    fn a_refused_setting_says_which_and_what_value() {
        let e = Error::setting(
            Setting::Bits,
            Some("12".into()),
            Words::new().given(Setting::Bits, 12).text(": use 8 or 16"),
        );
        assert!(matches!(&e, Error::Usage { setting: Some(Setting::Bits), value: Some(v), .. } if v == "12"));
        assert_eq!(e.worded(&Flags), "--bits 12: use 8 or 16");
        assert_eq!(e.to_string(), "bits=12: use 8 or 16");
    }

    #[test]
    fn every_setting_has_its_own_name() {
        let names: std::collections::BTreeSet<&str> = Setting::EVERY.iter().map(|s| s.name()).collect();
        assert_eq!(names.len(), Setting::EVERY.len());
        assert!(names.iter().all(|n| n.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')));
    }
}
