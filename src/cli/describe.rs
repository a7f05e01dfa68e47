//! `taction describe --descriptor NAME --image FILE.csv`: the feature vectors of one tactile image
//! (Sec. IV-B), one per line, comma-separated (the image CSV format of `taction sense`).

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use taction::describe::{DescriptorKind, DescriptorParams, Feature, ParamsError};
use taction::tactile::{ImageError, TactileImage};

#[derive(Debug, Args)]
pub struct DescribeArgs {
    /// vectorize | sift | mr8 | moment-normalized | polar-fourier | mnti | shape-index
    #[arg(long, value_name = "NAME", value_parser = parse_kind)]
    pub descriptor: DescriptorKind,
    /// The tactile image: rows of comma-separated values in [0, 1].
    #[arg(long, value_name = "FILE.csv")]
    pub image: PathBuf,
    /// Descriptor parameters as JSON, e.g. `{"descriptor": "mr8", "stride_px": 2}` (as a trained
    /// model stores them); omitted fields take their defaults. Must name the same descriptor.
    #[arg(long, value_name = "FILE.json")]
    pub params: Option<PathBuf>,
}

/// What can go wrong, each naming the file at fault.
#[derive(Debug, thiserror::Error)]
pub enum DescribeCommandError {
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error("{path}: {what}")]
    ParamsFile { path: String, what: String },
    #[error("{path}: describes {found}, but --descriptor is {wanted}")]
    Mismatch {
        path: String,
        found: &'static str,
        wanted: &'static str,
    },
    #[error("{path}: {source}")]
    BadParams { path: String, source: ParamsError },
    #[error("writing the features: {0}")]
    Output(#[from] std::io::Error),
}

fn parse_kind(name: &str) -> Result<DescriptorKind, String> {
    DescriptorKind::from_name(name).ok_or_else(|| {
        let known: Vec<&str> = DescriptorKind::ALL.iter().map(|k| k.name()).collect();
        format!(
            "unknown descriptor '{name}'; expected one of {}",
            known.join(", ")
        )
    })
}

/// The parameters in `path`, checked against `wanted`.
fn read_params(path: &Path, wanted: DescriptorKind) -> Result<DescriptorParams, DescribeCommandError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| DescribeCommandError::ParamsFile {
        path: name.clone(),
        what: e.to_string(),
    })?;
    let file_error = |what: String| DescribeCommandError::ParamsFile {
        path: name.clone(),
        what,
    };
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| file_error(e.to_string()))?;
    // A trained model's file keeps its descriptor's parameters under "descriptor".
    let value = match value.get("descriptor") {
        Some(inner @ serde_json::Value::Object(_)) => inner.clone(),
        _ => value,
    };
    // The descriptor is named before its fields are read: another descriptor's fields would
    // otherwise be reported as unknown fields of this one.
    let found = value
        .get("descriptor")
        .and_then(serde_json::Value::as_str)
        .and_then(DescriptorKind::from_name)
        .ok_or_else(|| {
            file_error(
                "want a JSON object naming its \"descriptor\" (e.g. {\"descriptor\": \"mr8\", \"stride_px\": 2}), \
                 or a trained model's file"
                    .into(),
            )
        })?;
    if found != wanted {
        return Err(DescribeCommandError::Mismatch {
            path: name,
            found: found.name(),
            wanted: wanted.name(),
        });
    }
    serde_json::from_value(value).map_err(|e| file_error(e.to_string()))
}

/// Writes `features` one per line, values comma-separated in shortest round-trip form.
fn write_features(out: &mut impl Write, features: &[Feature]) -> std::io::Result<()> {
    for feature in features {
        let line: Vec<String> = feature.iter().map(|v| v.to_string()).collect();
        writeln!(out, "{}", line.join(","))?;
    }
    out.flush()
}

fn describe(args: &DescribeArgs, out: &mut impl Write) -> Result<(), DescribeCommandError> {
    let params = match &args.params {
        Some(path) => read_params(path, args.descriptor)?,
        None => args.descriptor.default_params(),
    };
    let descriptor =
        DescriptorKind::build_with(&params).map_err(|source| DescribeCommandError::BadParams {
            path: args
                .params
                .as_deref()
                .map_or_else(String::new, |p| p.display().to_string()),
            source,
        })?;
    let image = TactileImage::read_csv(&args.image)?;
    write_features(out, &descriptor.describe(&image))?;
    Ok(())
}

/// Reads the image, describes it, prints the features to stdout.
pub fn run(args: &DescribeArgs) -> Result<(), Box<dyn std::error::Error>> {
    let stdout = std::io::stdout();
    describe(args, &mut std::io::BufWriter::new(stdout.lock()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(dir: &Path, params: Option<&str>) -> DescribeArgs {
        let image = dir.join("image.csv");
        std::fs::write(&image, "0,0.5,1\n0.25,0.75,0\n").unwrap();
        let params = params.map(|text| {
            let path = dir.join("params.json");
            std::fs::write(&path, text).unwrap();
            path
        });
        DescribeArgs {
            descriptor: DescriptorKind::Vectorize,
            image,
            params,
        }
    }

    #[test]
    fn prints_columns_for_vectorize() {
        let dir = tempfile::tempdir().unwrap();
        let mut out = Vec::new();
        describe(&args(dir.path(), None), &mut out).unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), "0,0.25,0.5,0.75,1,0\n");
    }

    #[test]
    fn params_must_name_the_same_descriptor_and_be_valid() {
        let dir = tempfile::tempdir().unwrap();
        let e = describe(
            &args(dir.path(), Some(r#"{"descriptor":"sift"}"#)),
            &mut Vec::new(),
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("params.json: describes sift, but --descriptor is vectorize"),
            "{e}"
        );
        let mut sift = args(dir.path(), Some(r#"{"descriptor":"sift","clamp":2}"#));
        sift.descriptor = DescriptorKind::Sift;
        let e = describe(&sift, &mut Vec::new()).unwrap_err();
        assert!(
            e.to_string().contains("params.json") && e.to_string().contains("sift.clamp"),
            "{e}"
        );
        let e = describe(&args(dir.path(), Some("{")), &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("params.json"), "{e}");
        // Another descriptor's fields: the descriptor named, not its fields reported unknown.
        let e = describe(
            &args(dir.path(), Some(r#"{"descriptor":"mr8","stride_px":2}"#)),
            &mut Vec::new(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("describes mr8"), "{e}");
        let e = describe(&args(dir.path(), Some("[1]")), &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("naming its \"descriptor\""), "{e}");
        // A trained model's file: its descriptor's parameters.
        let model = r#"{"format_version": 9, "descriptor": {"descriptor": "vectorize"}, "bag": {}}"#;
        let mut out = Vec::new();
        describe(&args(dir.path(), Some(model)), &mut out).unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), "0,0.25,0.5,0.75,1,0\n");
        assert!(parse_kind("hog").unwrap_err().contains("moment-normalized"));
    }
}
