//! The addresses at which the page can be opened, for printing: a server
//! bound to `0.0.0.0` listens on every address of the machine, but
//! `0.0.0.0` itself is not an address a tablet can open.

use std::net::{IpAddr, SocketAddr};

use crate::Scheme;

/// The hosts at which a server bound to `bound` is reached, those other
/// machines can use first:
///
/// - a specific address: that address alone;
/// - `0.0.0.0` (or `::`): this machine's interface addresses of the same
///   family, loopback last. IPv6 link-local addresses (`fe80::/10`) are left
///   out: a URL needs a zone for them, which browsers do not accept.
///
/// Interfaces are listed with the `if-addrs` crate (one `getifaddrs` call;
/// no traffic is sent). The error is the system's, if listing fails.
pub fn reachable_hosts(bound: IpAddr) -> std::io::Result<Vec<IpAddr>> {
    if !bound.is_unspecified() {
        return Ok(vec![bound]);
    }
    let interfaces = if_addrs::get_if_addrs()?;
    Ok(hosts_for_unspecified(
        bound,
        interfaces.iter().map(|i| i.ip()),
    ))
}

/// The hosts to print for a server listening on `addr`
/// ([`reachable_hosts`] of its IP), never empty; the error says why there
/// are none and what to set instead.
pub fn hosts_to_print(addr: SocketAddr) -> Result<Vec<IpAddr>, String> {
    let hosts = reachable_hosts(addr.ip()).map_err(|e| {
        format!(
            "listening on {addr}, but cannot list this machine's addresses to print \
             the page's URL ({e}); set `bind` to the address to use"
        )
    })?;
    if hosts.is_empty() {
        return Err(format!(
            "listening on {addr}, but this machine has no address of that kind to open \
             the page at; set `bind` to the address to use"
        ));
    }
    Ok(hosts)
}

/// Which of the machine's `addrs` a server bound to the unspecified
/// address `bound` listens on, in the order to print them.
fn hosts_for_unspecified(bound: IpAddr, addrs: impl Iterator<Item = IpAddr>) -> Vec<IpAddr> {
    let mut hosts: Vec<IpAddr> = Vec::new();
    for ip in addrs {
        let usable = match ip {
            IpAddr::V4(_) => bound.is_ipv4(),
            IpAddr::V6(v6) => bound.is_ipv6() && !v6.is_unicast_link_local(),
        };
        if usable && !ip.is_unspecified() && !hosts.contains(&ip) {
            hosts.push(ip);
        }
    }
    // Stable: interfaces keep the system's order within each group.
    hosts.sort_by_key(|ip| ip.is_loopback());
    hosts
}

/// The page's URL at `host`.
///
/// ```
/// use hil_http::urls::page_url;
/// let v6 = "::1".parse().unwrap();
/// assert_eq!(page_url(v6, 8765, "abc"), "http://[::1]:8765/abc/");
/// ```
pub fn page_url(host: IpAddr, port: u16, token: &str) -> String {
    page_url_over(Scheme::Http, host, port, token)
}

/// The page's URL at `host`, over `scheme`.
///
/// ```
/// use hil_http::{Scheme, urls::page_url_over};
/// let ip = "127.0.0.1".parse().unwrap();
/// assert_eq!(page_url_over(Scheme::Https, ip, 8765, "abc"), "https://127.0.0.1:8765/abc/");
/// ```
pub fn page_url_over(scheme: Scheme, host: IpAddr, port: u16, token: &str) -> String {
    let scheme = scheme.as_str();
    match host {
        IpAddr::V4(ip) => format!("{scheme}://{ip}:{port}/{token}/"),
        IpAddr::V6(ip) => format!("{scheme}://[{ip}]:{port}/{token}/"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ips(list: &[&str]) -> Vec<IpAddr> {
        list.iter().map(|s| s.parse().unwrap()).collect()
    }

    #[test]
    fn unspecified_binds_list_their_family_loopback_last() {
        let machine = ips(&[
            "127.0.0.1",
            "::1",
            "192.168.1.20",
            "fe80::1",
            "fd00::2",
            "10.0.0.5",
            "192.168.1.20",
        ]);
        let v4 = hosts_for_unspecified(ips(&["0.0.0.0"])[0], machine.iter().copied());
        assert_eq!(v4, ips(&["192.168.1.20", "10.0.0.5", "127.0.0.1"]));
        let v6 = hosts_for_unspecified(ips(&["::"])[0], machine.iter().copied());
        assert_eq!(v6, ips(&["fd00::2", "::1"]));
    }

    #[test]
    fn a_specific_bind_is_its_own_host() {
        for ip in ips(&["127.0.0.1", "192.168.1.20", "::1"]) {
            assert_eq!(reachable_hosts(ip).unwrap(), vec![ip]);
        }
    }
}
