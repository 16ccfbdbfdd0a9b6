//! The XML of an SSP's files read into a small element tree.

use crate::error::{Error, Result};
use std::path::Path;

/// A small element tree of an XML document (local names, namespaces dropped).
#[derive(Debug, Clone, Default)]
pub(crate) struct Element {
    pub(crate) name: String,
    pub(crate) attributes: Vec<(String, String)>,
    pub(crate) children: Vec<Element>,
}

impl Element {
    pub(crate) fn attr(&self, name: &str) -> Option<&str> {
        self.attributes.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
    pub(crate) fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }
    pub(crate) fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
}

pub(crate) fn parse_xml(text: &str, path: &Path) -> Result<Element> {
    use quick_xml::events::Event;
    let err = |reason: String| Error::Ssp { path: path.to_path_buf(), reason };
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack: Vec<Element> = vec![Element::default()];
    let open = |e: &quick_xml::events::BytesStart| -> Result<Element> {
        let mut el =
            Element { name: String::from_utf8_lossy(e.local_name().as_ref()).into_owned(), ..Element::default() };
        // a hash set for duplicates: quick-xml's own check is quadratic in the attributes
        let mut keys = std::collections::HashSet::new();
        for a in e.attributes().with_checks(false) {
            let a = a.map_err(|x| err(format!("malformed XML attribute: {x}")))?;
            if !keys.insert(a.key.as_ref().to_vec()) {
                return Err(err(format!(
                    "attribute {} repeated in <{}>",
                    String::from_utf8_lossy(a.key.as_ref()),
                    el.name
                )));
            }
            let v = a.unescape_value().map_err(|x| err(format!("malformed XML attribute value: {x}")))?;
            el.attributes.push((String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned(), v.into_owned()));
        }
        Ok(el)
    };
    loop {
        let pos = reader.buffer_position();
        match reader.read_event() {
            Ok(Event::Start(e)) => {
                if stack.len() > 64 {
                    return Err(err("XML nested deeper than 64 elements".into()));
                }
                stack.push(open(&e)?)
            }
            Ok(Event::Empty(e)) => {
                let el = open(&e)?;
                if let Some(p) = stack.last_mut() {
                    p.children.push(el);
                }
            }
            Ok(Event::End(_)) => {
                let el = stack.pop().ok_or_else(|| err("unbalanced XML".into()))?;
                match stack.last_mut() {
                    Some(p) => p.children.push(el),
                    None => return Err(err("unbalanced XML".into())),
                }
            }
            Ok(Event::Eof) => break,
            Ok(_) => {}
            Err(e) => return Err(err(format!("malformed XML at byte {pos}: {e}"))),
        }
    }
    if stack.len() != 1 {
        return Err(err("XML ends inside an element".into()));
    }
    let mut root = stack.pop().unwrap_or_default();
    root.children.pop().ok_or_else(|| err("empty XML document".into()))
}
