// The link checker's settings (scripts/check-links): remark-validate-links checks, offline,
// that every relative link and image of the Markdown files points to a file or folder of
// the repository and every `#fragment` to a heading of its target (GitHub's slugs).
// `repository: false`: no hosted repository is assumed, so nothing is fetched and links
// given as full URLs are left alone.
import remarkValidateLinks from 'remark-validate-links'

export default {
  plugins: [[remarkValidateLinks, {repository: false}]]
}
