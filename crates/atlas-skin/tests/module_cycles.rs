//! The method's stages import downward only: no cycle among the modules of
//! `crates/atlas-skin/src`, outside `#[cfg(test)]` code.
//!
//! The sources are parsed with `syn` from `src/lib.rs` down through every `mod` item. Each
//! module's references to the crate's items (`use` trees, paths in code and types, paths in
//! macro arguments) are resolved to the module that owns the item, following `use`
//! re-exports (`crate::Decomposition` is `decomposition`'s). A reference from module `A` to
//! an item of module `B` is an edge between the two children of their closest common
//! ancestor that contain `A` and `B` (`skeleton/placement.rs` using `cuts::joint_roles` is
//! the edge `skeleton → cuts` among the crate's top-level modules); a module and its own
//! descendants are one unit and may use each other. Among the children of every module the
//! edges must form no cycle. A failure names each cycle with one reference per edge (file,
//! line and the path as written), so that the import to move is found at once.

use proc_macro2::{TokenStream, TokenTree};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// A module's path from the crate root (`[]` for the root, `["cuts", "split"]`).
type ModPath = Vec<String>;

/// One reference to a crate item, as written.
#[derive(Clone, Debug)]
struct Reference {
    /// The referenced path made absolute (from the crate root), before re-exports are
    /// followed.
    segments: Vec<String>,
    file: PathBuf,
    line: usize,
    written: String,
}

#[derive(Default, Debug)]
struct Module {
    children: BTreeSet<String>,
    /// Names brought into the module's scope by `use` (or re-exported by `pub use`), to
    /// the absolute path they stand for.
    imports: BTreeMap<String, Vec<String>>,
    references: Vec<Reference>,
}

/// Whether the attributes hold a `#[cfg(...)]` that mentions `test`: such code is compiled
/// only for the crate's own tests and may reach any module.
fn is_test_only(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|attr| {
        attr.path().is_ident("cfg")
            && attr
                .meta
                .require_list()
                .is_ok_and(|list| mentions_test(list.tokens.clone()))
    })
}

fn mentions_test(tokens: TokenStream) -> bool {
    tokens.into_iter().any(|token| match token {
        TokenTree::Ident(ident) => ident == "test",
        TokenTree::Group(group) => mentions_test(group.stream()),
        _ => false,
    })
}

/// The crate's modules, parsed from `src/lib.rs` down.
struct Crate {
    src: PathBuf,
    modules: BTreeMap<ModPath, Module>,
}

impl Crate {
    fn parse(src: &Path) -> Crate {
        let mut krate = Crate {
            src: src.to_path_buf(),
            modules: BTreeMap::new(),
        };
        let lib = src.join("lib.rs");
        let file = parse_file(&lib);
        krate.add_module(Vec::new(), &lib, src.to_path_buf(), &file.items);
        krate
    }

    /// Adds the module at `path` whose items are `items` (read from `file`); `dir` is where
    /// its child modules' files are.
    fn add_module(&mut self, path: ModPath, file: &Path, dir: PathBuf, items: &[syn::Item]) {
        let mut children = Vec::new();
        for item in items {
            if let syn::Item::Mod(module) = item {
                if is_test_only(&module.attrs) {
                    continue;
                }
                assert!(
                    !module.attrs.iter().any(|attr| attr.path().is_ident("path")),
                    "{}: `#[path]` on `mod {}` is not followed by this check",
                    file.display(),
                    module.ident
                );
                children.push(module);
            }
        }
        let module = Module {
            children: children.iter().map(|m| m.ident.to_string()).collect(),
            ..Module::default()
        };
        self.modules.insert(path.clone(), module);
        let mut collector = Collector {
            module: &path,
            children: &self.modules[&path].children.clone(),
            file: self.relative(file),
            imports: BTreeMap::new(),
            references: Vec::new(),
        };
        for item in items {
            collector.visit_item(item);
        }
        let (imports, references) = (collector.imports, collector.references);
        let entry = self.modules.get_mut(&path).expect("just inserted");
        entry.imports = imports;
        entry.references = references;

        for child in children {
            let name = child.ident.to_string();
            let mut child_path = path.clone();
            child_path.push(name.clone());
            match &child.content {
                Some((_, inline_items)) => {
                    self.add_module(child_path, file, dir.join(&name), inline_items)
                }
                None => {
                    let flat = dir.join(format!("{name}.rs"));
                    let (child_file, child_dir) = if flat.is_file() {
                        (flat, dir.join(&name))
                    } else {
                        (dir.join(&name).join("mod.rs"), dir.join(&name))
                    };
                    let parsed = parse_file(&child_file);
                    self.add_module(child_path, &child_file, child_dir, &parsed.items);
                }
            }
        }
    }

    fn relative(&self, file: &Path) -> PathBuf {
        file.strip_prefix(&self.src).unwrap_or(file).to_path_buf()
    }

    /// The module that owns the item `segments` (absolute) names: the deepest module the
    /// segments walk into, following the `use` names of each module on the way.
    fn owner(&self, segments: &[String], depth: usize) -> ModPath {
        let mut at: ModPath = Vec::new();
        for (i, segment) in segments.iter().enumerate() {
            let module = &self.modules[&at];
            if module.children.contains(segment) {
                at.push(segment.clone());
            } else if let Some(target) = module.imports.get(segment) {
                if depth > 16 || target.as_slice() == &segments[..=i] {
                    return at;
                }
                let mut rest = target.clone();
                rest.extend_from_slice(&segments[i + 1..]);
                return self.owner(&rest, depth + 1);
            } else {
                return at;
            }
        }
        at
    }
}

fn parse_file(file: &Path) -> syn::File {
    let text = std::fs::read_to_string(file)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", file.display()));
    syn::parse_file(&text).unwrap_or_else(|e| panic!("cannot parse {}: {e}", file.display()))
}

/// Gathers a module's `use` names and references to crate items, skipping test-only code
/// and the module's child modules (each gathered on its own).
struct Collector<'a> {
    module: &'a ModPath,
    children: &'a BTreeSet<String>,
    file: PathBuf,
    imports: BTreeMap<String, Vec<String>>,
    references: Vec<Reference>,
}

impl Collector<'_> {
    /// `segments` made absolute when they name a crate item (`crate::`, `super::`,
    /// `self::`, a child module, or a name this module imports); `None` for anything else
    /// (locals, the standard library, other crates, the module's own items).
    fn absolute(&self, segments: &[String]) -> Option<Vec<String>> {
        let first = segments.first()?;
        let mut base = self.module.clone();
        let mut rest = segments;
        match first.as_str() {
            "crate" => {
                base.clear();
                rest = &segments[1..];
            }
            "self" => rest = &segments[1..],
            "super" => {
                while rest.first().is_some_and(|s| s == "super") {
                    base.pop()?;
                    rest = &rest[1..];
                }
                if rest.first().is_some_and(|s| s == "self") {
                    rest = &rest[1..];
                }
            }
            name if self.children.contains(name) => {}
            name => {
                let target = self.imports.get(name)?;
                let mut out = target.clone();
                out.extend_from_slice(&segments[1..]);
                return Some(out);
            }
        }
        base.extend(rest.iter().cloned());
        Some(base)
    }

    fn refer(&mut self, segments: &[String], line: usize) {
        if let Some(absolute) = self.absolute(segments) {
            self.references.push(Reference {
                segments: absolute,
                file: self.file.clone(),
                line,
                written: segments.join("::"),
            });
        }
    }

    /// The leaves of a `use` tree, each as its path and the name it brings into scope.
    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree, line: usize) {
        match tree {
            syn::UseTree::Path(path) => {
                prefix.push(path.ident.to_string());
                self.use_tree(prefix, &path.tree, line);
                prefix.pop();
            }
            syn::UseTree::Name(name) => {
                let ident = name.ident.to_string();
                let mut full = prefix.clone();
                if ident != "self" {
                    full.push(ident.clone());
                }
                let bound = if ident == "self" {
                    prefix.last().cloned()
                } else {
                    Some(ident)
                };
                self.import(&full, bound, line);
            }
            syn::UseTree::Rename(rename) => {
                let mut full = prefix.clone();
                if rename.ident != "self" {
                    full.push(rename.ident.to_string());
                }
                self.import(&full, Some(rename.rename.to_string()), line);
            }
            syn::UseTree::Glob(_) => self.import(prefix, None, line),
            syn::UseTree::Group(group) => {
                for item in &group.items {
                    self.use_tree(prefix, item, line);
                }
            }
        }
    }

    fn import(&mut self, full: &[String], bound: Option<String>, line: usize) {
        let Some(absolute) = self.absolute(full) else {
            return;
        };
        self.references.push(Reference {
            segments: absolute.clone(),
            file: self.file.clone(),
            line,
            written: full.join("::"),
        });
        if let Some(name) = bound {
            self.imports.insert(name, absolute);
        }
    }

    /// Paths in a macro's tokens (`matches!(x, crate::a::B)`, `format!("{}", super::C)`).
    fn macro_tokens(&mut self, tokens: TokenStream) {
        let tokens: Vec<TokenTree> = tokens.into_iter().collect();
        let mut i = 0;
        while i < tokens.len() {
            if let TokenTree::Group(group) = &tokens[i] {
                self.macro_tokens(group.stream());
                i += 1;
                continue;
            }
            let TokenTree::Ident(first) = &tokens[i] else {
                i += 1;
                continue;
            };
            let line = first.span().start().line;
            let mut segments = vec![first.to_string()];
            let mut j = i + 1;
            while let (
                Some(TokenTree::Punct(a)),
                Some(TokenTree::Punct(b)),
                Some(TokenTree::Ident(next)),
            ) = (tokens.get(j), tokens.get(j + 1), tokens.get(j + 2))
            {
                if a.as_char() != ':' || b.as_char() != ':' {
                    break;
                }
                segments.push(next.to_string());
                j += 3;
            }
            let preceded_by_path = i >= 2
                && matches!((&tokens[i - 1], &tokens[i - 2]),
                    (TokenTree::Punct(a), TokenTree::Punct(b)) if a.as_char() == ':' && b.as_char() == ':');
            if segments.len() > 1 && !preceded_by_path {
                self.refer(&segments, line);
            }
            i = j;
        }
    }
}

impl<'ast> Visit<'ast> for Collector<'_> {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        let attrs: &[syn::Attribute] = match item {
            syn::Item::Const(i) => &i.attrs,
            syn::Item::Enum(i) => &i.attrs,
            syn::Item::Fn(i) => &i.attrs,
            syn::Item::Impl(i) => &i.attrs,
            syn::Item::Macro(i) => &i.attrs,
            syn::Item::Mod(_) => return,
            syn::Item::Static(i) => &i.attrs,
            syn::Item::Struct(i) => &i.attrs,
            syn::Item::Trait(i) => &i.attrs,
            syn::Item::Type(i) => &i.attrs,
            syn::Item::Union(i) => &i.attrs,
            syn::Item::Use(i) => &i.attrs,
            _ => &[],
        };
        if !is_test_only(attrs) {
            syn::visit::visit_item(self, item);
        }
    }

    fn visit_impl_item(&mut self, item: &'ast syn::ImplItem) {
        let attrs: &[syn::Attribute] = match item {
            syn::ImplItem::Const(i) => &i.attrs,
            syn::ImplItem::Fn(i) => &i.attrs,
            syn::ImplItem::Type(i) => &i.attrs,
            syn::ImplItem::Macro(i) => &i.attrs,
            _ => &[],
        };
        if !is_test_only(attrs) {
            syn::visit::visit_impl_item(self, item);
        }
    }

    fn visit_item_use(&mut self, item: &'ast syn::ItemUse) {
        let line = item.use_token.span.start().line;
        self.use_tree(&mut Vec::new(), &item.tree, line);
    }

    fn visit_path(&mut self, path: &'ast syn::Path) {
        if path.leading_colon.is_none() && path.segments.len() > 1 {
            let segments: Vec<String> = path.segments.iter().map(|s| s.ident.to_string()).collect();
            let line = path.segments[0].ident.span().start().line;
            self.refer(&segments, line);
        }
        syn::visit::visit_path(self, path);
    }

    fn visit_macro(&mut self, mac: &'ast syn::Macro) {
        self.visit_path(&mac.path);
        self.macro_tokens(mac.tokens.clone());
    }
}

/// One edge between two sibling modules, with the first reference that makes it.
struct Edge {
    reference: Reference,
}

/// The edges among the children of each module: `parent → (from, to) → first reference`.
fn sibling_edges(krate: &Crate) -> BTreeMap<ModPath, BTreeMap<(String, String), Edge>> {
    let mut edges: BTreeMap<ModPath, BTreeMap<(String, String), Edge>> = BTreeMap::new();
    for (from, module) in &krate.modules {
        for reference in &module.references {
            let to = krate.owner(&reference.segments, 0);
            let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
            if common == from.len() || common == to.len() {
                continue; // a module and its ancestors or descendants
            }
            let parent = from[..common].to_vec();
            edges
                .entry(parent)
                .or_default()
                .entry((from[common].clone(), to[common].clone()))
                .or_insert_with(|| Edge {
                    reference: reference.clone(),
                });
        }
    }
    edges
}

/// The strongly connected components of more than one node (Tarjan 1972).
fn cycles(nodes: &BTreeSet<String>, edges: &BTreeMap<(String, String), Edge>) -> Vec<Vec<String>> {
    struct Tarjan<'a> {
        next: &'a BTreeMap<&'a str, Vec<&'a str>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        components: Vec<Vec<String>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on_stack.insert(v);
            for &w in self.next.get(v).into_iter().flatten() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.low[v].min(self.low[w]);
                    self.low.insert(v, low);
                } else if self.on_stack.contains(w) {
                    let low = self.low[v].min(self.index[w]);
                    self.low.insert(v, low);
                }
            }
            if self.low[v] == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    component.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    component.sort();
                    self.components.push(component);
                }
            }
        }
    }
    let mut next: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for (from, to) in edges.keys() {
        next.entry(from.as_str()).or_default().push(to.as_str());
    }
    let mut tarjan = Tarjan {
        next: &next,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        components: Vec::new(),
    };
    for node in nodes {
        if !tarjan.index.contains_key(node.as_str()) {
            tarjan.visit(node);
        }
    }
    tarjan.components
}

/// One cycle through `component`, as a closed walk of module names, found by a
/// breadth-first search back to its first node.
fn one_cycle(component: &[String], edges: &BTreeMap<(String, String), Edge>) -> Vec<String> {
    let inside: BTreeSet<&str> = component.iter().map(String::as_str).collect();
    let start = component[0].as_str();
    let mut came_from: BTreeMap<&str, &str> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([start]);
    while let Some(v) = queue.pop_front() {
        for (from, to) in edges.keys() {
            if from != v || !inside.contains(to.as_str()) {
                continue;
            }
            if to == start {
                // The path start → … → v, then back to start.
                let mut back = vec![v];
                while let Some(&previous) = came_from.get(back[back.len() - 1]) {
                    back.push(previous);
                }
                let mut walk: Vec<String> = back.iter().rev().map(|s| s.to_string()).collect();
                walk.push(start.to_string());
                return walk;
            }
            if !came_from.contains_key(to.as_str()) && to != start {
                came_from.insert(to, v);
                queue.push_back(to);
            }
        }
    }
    unreachable!("a strongly connected component holds a cycle through each of its nodes")
}

/// A report of every cycle among sibling modules, empty when there is none.
fn cycle_report(krate: &Crate) -> String {
    let mut report = String::new();
    for (parent, edges) in sibling_edges(krate) {
        let children = &krate.modules[&parent].children;
        let scope = if parent.is_empty() {
            "the crate root".to_string()
        } else {
            format!("`{}`", parent.join("::"))
        };
        for component in cycles(children, &edges) {
            let walk = one_cycle(&component, &edges);
            writeln!(
                report,
                "cycle among the modules of {scope}: {}",
                walk.join(" → ")
            )
            .unwrap();
            writeln!(
                report,
                "  modules on cycles with it: {}; the edges between them:",
                component.join(", ")
            )
            .unwrap();
            for ((from, to), edge) in &edges {
                if component.contains(from) && component.contains(to) {
                    let r = &edge.reference;
                    writeln!(
                        report,
                        "  {from} → {to}: {}:{} uses `{}`",
                        r.file.display(),
                        r.line,
                        r.written
                    )
                    .unwrap();
                }
            }
        }
    }
    report
}

/// The order in which the crate root's modules may be read, each using only modules
/// before it (a topological order of the root's edges; ties by name).
fn reading_order(krate: &Crate) -> Vec<String> {
    let edges = sibling_edges(krate).remove(&Vec::new()).unwrap_or_default();
    let mut left: BTreeSet<String> = krate.modules[&Vec::new()].children.clone();
    let mut order = Vec::new();
    while !left.is_empty() {
        let ready = left
            .iter()
            .find(|m| {
                !edges
                    .keys()
                    .any(|(from, to)| from == *m && to != *m && left.contains(to))
            })
            .cloned();
        let Some(ready) = ready else { break };
        left.remove(&ready);
        order.push(ready);
    }
    order
}

fn method_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn no_cycle_among_the_method_modules() {
    let krate = Crate::parse(&method_src());
    let report = cycle_report(&krate);
    assert!(
        report.is_empty(),
        "the stages must import downward only:\n{report}"
    );
    println!(
        "the method's modules, each using only those before it: {}",
        reading_order(&krate).join(", ")
    );
}

/// The check finds a cycle where one is, names both edges, and ignores test-only code.
#[test]
fn a_cycle_is_found_and_named() {
    let dir = std::env::temp_dir().join(format!("module_cycles_{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(src.join("stage_b")).unwrap();
    std::fs::write(
        src.join("lib.rs"),
        "pub mod stage_a;\npub mod stage_b;\npub mod stage_c;\npub use stage_a::Thing;\n",
    )
    .unwrap();
    std::fs::write(
        src.join("stage_a.rs"),
        "pub struct Thing;\npub fn f() -> crate::stage_b::inner::Other { todo!() }\n",
    )
    .unwrap();
    std::fs::write(src.join("stage_b/mod.rs"), "pub mod inner;\n").unwrap();
    std::fs::write(
        src.join("stage_b/inner.rs"),
        "use crate::Thing;\npub struct Other(Thing);\n",
    )
    .unwrap();
    std::fs::write(
        src.join("stage_c.rs"),
        "#[cfg(test)]\nmod tests { use crate::stage_a::Thing; }\n\
         #[cfg(test)]\nfn helper() { let _ = crate::stage_b::inner::Other; }\n\
         pub fn g() { let _ = matches!(1, 1); }\n",
    )
    .unwrap();
    let report = cycle_report(&Crate::parse(&src));
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        report.contains("cycle among the modules of the crate root: stage_a → stage_b → stage_a"),
        "{report}"
    );
    assert!(
        report.contains("stage_a → stage_b: stage_a.rs:2 uses `crate::stage_b::inner::Other`"),
        "{report}"
    );
    assert!(
        report.contains("stage_b → stage_a: stage_b/inner.rs:1 uses `crate::Thing`"),
        "{report}"
    );
    assert!(!report.contains("stage_c"), "{report}");
}

/// The rows of the stage table in `lib.rs`'s documentation, each as the module names its
/// last column links to (`` [`cuts`] ``, `` [`decompose()`] `` for the module of that
/// function).
fn lib_table_rows(lib: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(lib).unwrap();
    text.lines()
        .filter_map(|line| line.strip_prefix("//! |"))
        .skip(2) // the header and its separator
        .map(|row| {
            let last = row
                .trim_end()
                .trim_end_matches('|')
                .rsplit('|')
                .next()
                .unwrap();
            last.split("[`")
                .skip(1)
                .map(|link| {
                    let name = link.split('`').next().unwrap();
                    name.trim_end_matches("()").to_string()
                })
                .collect()
        })
        .collect()
}

/// `lib.rs`'s table lists every top-level module once, in an order where each imports only
/// modules of its own row or the rows above (what "stages import downward only" means for
/// a reader of the table).
#[test]
fn the_lib_table_lists_every_module_in_import_order() {
    let src = method_src();
    let krate = Crate::parse(&src);
    let rows = lib_table_rows(&src.join("lib.rs"));
    let row_of: BTreeMap<&str, usize> = rows
        .iter()
        .enumerate()
        .flat_map(|(i, names)| names.iter().map(move |n| (n.as_str(), i)))
        .collect();
    let modules = &krate.modules[&Vec::new()].children;
    let missing: Vec<&String> = modules
        .iter()
        .filter(|m| !row_of.contains_key(m.as_str()))
        .collect();
    assert!(
        missing.is_empty(),
        "lib.rs's table does not list {missing:?}"
    );
    let unknown: Vec<&&str> = row_of.keys().filter(|n| !modules.contains(**n)).collect();
    assert!(
        unknown.is_empty(),
        "lib.rs's table lists no module {unknown:?}"
    );
    let mut upward = String::new();
    let edges = sibling_edges(&krate)
        .remove(&Vec::new())
        .unwrap_or_default();
    for ((from, to), edge) in &edges {
        if row_of[to.as_str()] > row_of[from.as_str()] {
            let r = &edge.reference;
            writeln!(
                upward,
                "  {from} uses {to}, listed below it: {}:{} uses `{}`",
                r.file.display(),
                r.line,
                r.written
            )
            .unwrap();
        }
    }
    assert!(
        upward.is_empty(),
        "lib.rs's table lists a module above one it uses:\n{upward}"
    );
}
