//! A self-signed X.509 certificate for an ECDSA P-256 key, written in DER
//! by hand: the few fields browsers and rustls need (version 3, a random
//! serial, the subject as issuer, a validity that never lapses, the public
//! key, and the host names and addresses as subjectAltName) and nothing
//! else. A certificate library would pull in a DER writer, a date crate
//! and a PEM crate for this one use; `ring` (which rustls uses anyway)
//! makes the key and the signature.

use std::net::IpAddr;

use base64::Engine as _;
use ring::rand::{SecureRandom, SystemRandom};
use ring::signature::{ECDSA_P256_SHA256_ASN1_SIGNING, EcdsaKeyPair, KeyPair};

/// The subject's common name.
const COMMON_NAME: &str = "hil (self-signed)";

// Object identifiers, DER-encoded with their tag and length.
/// ecdsa-with-SHA256 (1.2.840.10045.4.3.2).
const ECDSA_WITH_SHA256: &[u8] = &[0x06, 0x08, 0x2A, 0x86, 0x48, 0xCE, 0x3D, 0x04, 0x03, 0x02];
/// id-ecPublicKey (1.2.840.10045.2.1).
const EC_PUBLIC_KEY: &[u8] = &[0x06, 0x07, 0x2A, 0x86, 0x48, 0xCE, 0x3D, 0x02, 0x01];
/// prime256v1 (1.2.840.10045.3.1.7).
const PRIME256V1: &[u8] = &[0x06, 0x08, 0x2A, 0x86, 0x48, 0xCE, 0x3D, 0x03, 0x01, 0x07];
/// commonName (2.5.4.3).
const COMMON_NAME_OID: &[u8] = &[0x06, 0x03, 0x55, 0x04, 0x03];
/// subjectAltName (2.5.29.17).
const SUBJECT_ALT_NAME: &[u8] = &[0x06, 0x03, 0x55, 0x1D, 0x11];

/// Valid from 1 January 1975 (UTCTime) to 1 January 4096
/// (GeneralizedTime): the person trusts the certificate by its
/// fingerprint, so an expiry would only break a kept data folder.
const NOT_BEFORE: &[u8] = b"750101000000Z";
const NOT_AFTER: &[u8] = b"40960101000000Z";

/// A self-signed certificate and its key, both PEM.
pub(crate) struct SelfSigned {
    /// `-----BEGIN CERTIFICATE-----`.
    pub cert_pem: String,
    /// `-----BEGIN PRIVATE KEY-----` (PKCS#8).
    pub key_pem: String,
}

/// Why a certificate could not be made (the system's random source or
/// the signer failed).
#[derive(Debug)]
pub(crate) struct Unavailable(&'static str);

impl std::fmt::Display for Unavailable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

/// A new key and a certificate for `names`: each an IP address (written
/// as one) or a host name.
pub(crate) fn make(names: &[String]) -> Result<SelfSigned, Unavailable> {
    let rng = SystemRandom::new();
    let pkcs8 = EcdsaKeyPair::generate_pkcs8(&ECDSA_P256_SHA256_ASN1_SIGNING, &rng)
        .map_err(|_| Unavailable("the system's random source failed"))?;
    let key = EcdsaKeyPair::from_pkcs8(&ECDSA_P256_SHA256_ASN1_SIGNING, pkcs8.as_ref(), &rng)
        .map_err(|_| Unavailable("the new key was rejected"))?;
    let mut serial = [0u8; 16];
    rng.fill(&mut serial)
        .map_err(|_| Unavailable("the system's random source failed"))?;
    // A positive INTEGER with no leading zero byte.
    serial[0] = (serial[0] & 0x7F) | 0x40;

    let algorithm = sequence(&[ECDSA_WITH_SHA256]);
    let name = sequence(&[&set(&[&sequence(&[
        COMMON_NAME_OID,
        &tlv(0x0C, COMMON_NAME.as_bytes()),
    ])])]);
    let validity = sequence(&[&tlv(0x17, NOT_BEFORE), &tlv(0x18, NOT_AFTER)]);
    let public_key = sequence(&[
        &sequence(&[EC_PUBLIC_KEY, PRIME256V1]),
        &bit_string(key.public_key().as_ref()),
    ]);
    let extensions = tlv(
        0xA3,
        &sequence(&[&sequence(&[
            SUBJECT_ALT_NAME,
            &tlv(0x04, &subject_alt_names(names)),
        ])]),
    );
    let tbs = sequence(&[
        &tlv(0xA0, &tlv(0x02, &[2])), // version 3
        &tlv(0x02, &serial),
        &algorithm,
        &name,
        &validity,
        &name,
        &public_key,
        &extensions,
    ]);
    let signature = key
        .sign(&rng, &tbs)
        .map_err(|_| Unavailable("signing the certificate failed"))?;
    let cert = sequence(&[&tbs, &algorithm, &bit_string(signature.as_ref())]);
    Ok(SelfSigned {
        cert_pem: pem("CERTIFICATE", &cert),
        key_pem: pem("PRIVATE KEY", pkcs8.as_ref()),
    })
}

/// GeneralNames: an iPAddress for each name that parses as one, else a
/// dNSName.
fn subject_alt_names(names: &[String]) -> Vec<u8> {
    let entries: Vec<Vec<u8>> = names
        .iter()
        .map(|n| match n.parse::<IpAddr>() {
            Ok(IpAddr::V4(ip)) => tlv(0x87, &ip.octets()),
            Ok(IpAddr::V6(ip)) => tlv(0x87, &ip.octets()),
            Err(_) => tlv(0x82, n.as_bytes()),
        })
        .collect();
    sequence(&entries.iter().map(Vec::as_slice).collect::<Vec<_>>())
}

/// One DER element: tag, definite length, contents.
fn tlv(tag: u8, contents: &[u8]) -> Vec<u8> {
    let len = contents.len();
    let mut out = vec![tag];
    if len < 0x80 {
        out.push(len as u8);
    } else {
        let bytes = len.to_be_bytes();
        let skip = bytes.iter().take_while(|&&b| b == 0).count();
        out.push(0x80 | (bytes.len() - skip) as u8);
        out.extend_from_slice(&bytes[skip..]);
    }
    out.extend_from_slice(contents);
    out
}

fn sequence(parts: &[&[u8]]) -> Vec<u8> {
    tlv(0x30, &parts.concat())
}

fn set(parts: &[&[u8]]) -> Vec<u8> {
    tlv(0x31, &parts.concat())
}

/// A BIT STRING of whole bytes (no unused bits).
fn bit_string(bytes: &[u8]) -> Vec<u8> {
    tlv(0x03, &[&[0u8][..], bytes].concat())
}

/// PEM: the label's armour around the DER in base64, 64 columns a line.
fn pem(label: &str, der: &[u8]) -> String {
    let body = base64::engine::general_purpose::STANDARD.encode(der);
    let mut out = format!("-----BEGIN {label}-----\n");
    for line in body.as_bytes().chunks(64) {
        // base64 is ASCII.
        out.push_str(std::str::from_utf8(line).unwrap_or_default());
        out.push('\n');
    }
    out.push_str(&format!("-----END {label}-----\n"));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_use_the_short_form_below_128_and_the_long_form_above() {
        assert_eq!(tlv(0x04, &[7; 3])[..2], [0x04, 3]);
        assert_eq!(tlv(0x04, &[7; 127])[..2], [0x04, 127]);
        assert_eq!(tlv(0x04, &[7; 128])[..3], [0x04, 0x81, 128]);
        assert_eq!(tlv(0x04, &[7; 300])[..4], [0x04, 0x82, 0x01, 0x2C]);
    }

    #[test]
    fn addresses_are_ip_entries_and_the_rest_host_names() {
        let san = subject_alt_names(&["localhost".into(), "127.0.0.1".into(), "::1".into()]);
        let mut expected = tlv(0x82, b"localhost");
        expected.extend(tlv(0x87, &[127, 0, 0, 1]));
        let mut v6 = [0u8; 16];
        v6[15] = 1;
        expected.extend(tlv(0x87, &v6));
        assert_eq!(san, tlv(0x30, &expected));
    }

    #[test]
    fn pem_wraps_base64_at_64_columns() {
        let p = pem("CERTIFICATE", &[0xAB; 100]);
        let lines: Vec<&str> = p.lines().collect();
        assert_eq!(lines[0], "-----BEGIN CERTIFICATE-----");
        assert_eq!(lines[1].len(), 64);
        assert_eq!(*lines.last().unwrap(), "-----END CERTIFICATE-----");
    }
}
