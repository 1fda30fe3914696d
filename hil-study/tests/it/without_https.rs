//! A hil-study built without the feature `https` (no rustls or ring):
//! whatever asks for HTTPS (a config key, or `--lan` setting the address
//! after the config was read) is an error naming that key, and nothing is
//! served in plain HTTP instead. `bash scripts/test` runs this file in a
//! build of its own (`cargo test -p hil-study --test it`).

use hil_core::HilError;
use hil_study::{StudyConfig, StudyServer};

fn field_of(e: &HilError) -> Option<&str> {
    match e {
        HilError::Config(c) => c.field.as_deref(),
        HilError::InvalidParameter { name, .. } => Some(name),
        _ => None,
    }
}

#[test]
fn each_key_that_asks_for_https_is_named() {
    for (text, field) in [
        ("[server]\nhttps = true\n", "server.https"),
        ("[server]\nbind = \"0.0.0.0\"\n", "server.bind"),
        (
            "[server]\ntls_cert = \"c.pem\"\ntls_key = \"k.pem\"\n",
            "server.tls_cert",
        ),
    ] {
        let e = StudyConfig::parse(text, "study.toml".as_ref()).unwrap_err();
        assert!(matches!(e, HilError::Config(_)), "{text}: {e:?}");
        assert_eq!(field_of(&e), Some(field), "{text}: {e}");
        assert!(e.to_string().contains("study.toml"), "{e}");
    }
}

#[test]
fn serving_on_the_lan_is_refused_not_downgraded() {
    let dir = std::env::temp_dir().join(format!("hil-study-no-https-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut config = StudyConfig::default();
    // What `--lan` does after the config was read.
    config.server.bind = "0.0.0.0".parse().unwrap();
    let e = StudyServer::start(config, &dir).map(|_| ()).unwrap_err();
    assert!(
        matches!(&e, HilError::InvalidParameter { name, .. } if name == "server.bind"),
        "{e:?}"
    );
    // Nothing was made for HTTPS.
    assert!(!dir.join(hil_http::tls::SELF_SIGNED_CERT).exists());
    let _ = std::fs::remove_dir_all(&dir);
}
